#pragma once
// Plain structs for the messages the MAVLink adapter uses, with pack (struct -> Message) and
// unpack (Message -> struct, nullopt for another message id). Field names and units are
// common.xml's; the structs do not convert units, the adapter does.
#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "mavlink/fields.h"

namespace eamos::mavlink {

struct Heartbeat {
  uint8_t type = 0;             ///< MAV_TYPE
  uint8_t autopilot = 0;        ///< MAV_AUTOPILOT
  uint8_t base_mode = 0;        ///< MAV_MODE_FLAG bits (armed = 128)
  uint32_t custom_mode = 0;     ///< autopilot-specific flight mode
  uint8_t system_status = 0;    ///< MAV_STATE
  uint8_t mavlink_version = 3;  ///< always 3 for MAVLink 2
};

struct SysStatus {
  uint32_t sensors_present = 0;
  uint32_t sensors_enabled = 0;
  uint32_t sensors_health = 0;
  uint16_t load = 0;              ///< d%
  uint16_t voltage_battery = 0;   ///< mV, UINT16_MAX unknown
  int16_t current_battery = -1;   ///< cA, -1 unknown
  int8_t battery_remaining = -1;  ///< %, -1 unknown
  uint16_t drop_rate_comm = 0;    ///< c%
  uint16_t errors_comm = 0;
};

struct LocalPositionNed {
  uint32_t time_boot_ms = 0;
  float x = 0, y = 0, z = 0;     ///< m, north east down
  float vx = 0, vy = 0, vz = 0;  ///< m/s
};

struct GlobalPositionInt {
  uint32_t time_boot_ms = 0;
  int32_t lat = 0, lon = 0;     ///< degE7
  int32_t alt = 0;              ///< mm above mean sea level
  int32_t relative_alt = 0;     ///< mm above home
  int16_t vx = 0, vy = 0, vz = 0;  ///< cm/s, north east down
  uint16_t hdg = UINT16_MAX;    ///< cdeg, UINT16_MAX unknown
};

/// What an autopilot flying MAV_CMD_DO_ORBIT says of its circle (PX4, while in its Orbit
/// mode): the centre it circles, which the command may have left to the vehicle.
struct OrbitExecutionStatus {
  uint64_t time_usec = 0;
  float radius = 0;    ///< m; positive clockwise, negative counter-clockwise
  uint8_t frame = 0;   ///< MAV_FRAME of x, y, z
  int32_t x = 0, y = 0;  ///< global frames: degE7 (lat, lon); local frames: m * 1e4
  float z = 0;         ///< m, in `frame`
};

/// The vehicle's estimated attitude (ATTITUDE).
struct Attitude {
  uint32_t time_boot_ms = 0;
  float roll = 0, pitch = 0, yaw = 0;  ///< rad; yaw from north, clockwise
};

/// A simulator's true attitude, position and velocity (HIL_STATE_QUATERNION; PX4 SIH sends its
/// ground truth as this when asked): the rates and accelerations are not read.
struct HilStateQuaternion {
  uint64_t time_usec = 0;
  std::array<float, 4> attitude_quaternion{1, 0, 0, 0};  ///< w, x, y, z
  int32_t lat = 0, lon = 0;        ///< degE7
  int32_t alt = 0;                 ///< mm above mean sea level
  int16_t vx = 0, vy = 0, vz = 0;  ///< cm/s, north east down
};

struct CommandLong {
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  uint16_t command = 0;      ///< MAV_CMD
  uint8_t confirmation = 0;  ///< 0 first try, +1 per retry
  std::array<float, 7> param{};
};

struct CommandInt {
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  uint8_t frame = 0;  ///< MAV_FRAME
  uint16_t command = 0;
  uint8_t current = 0;
  uint8_t autocontinue = 0;
  std::array<float, 4> param{};
  int32_t x = 0, y = 0;  ///< degE7 or local m*1e4, by frame
  float z = 0;
};

struct CommandAck {
  uint16_t command = 0;
  uint8_t result = 0;        ///< MAV_RESULT
  uint8_t progress = 0;      ///< % while IN_PROGRESS
  int32_t result_param2 = 0;
  uint8_t target_system = 0;
  uint8_t target_component = 0;
};

struct SetPositionTargetLocalNed {
  uint32_t time_boot_ms = 0;
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  uint8_t coordinate_frame = 1;  ///< MAV_FRAME_LOCAL_NED
  uint16_t type_mask = 0;        ///< POSITION_TARGET_TYPEMASK: set bits are ignored
  float x = 0, y = 0, z = 0;
  float vx = 0, vy = 0, vz = 0;
  float afx = 0, afy = 0, afz = 0;
  float yaw = 0, yaw_rate = 0;
};

struct ExtendedSysState {
  uint8_t vtol_state = 0;    ///< MAV_VTOL_STATE
  uint8_t landed_state = 0;  ///< MAV_LANDED_STATE: 1 on ground, 2 in air, 3 taking off, 4 landing
};

struct BatteryStatus {
  uint8_t id = 0;
  uint8_t battery_function = 0;
  uint8_t type = 0;
  int16_t temperature = INT16_MAX;  ///< cdegC
  std::array<uint16_t, 10> voltages{};  ///< mV per cell, UINT16_MAX unused
  int16_t current_battery = -1;     ///< cA
  int32_t current_consumed = -1;    ///< mAh
  int32_t energy_consumed = -1;     ///< hJ
  int8_t battery_remaining = -1;    ///< %
  int32_t time_remaining = 0;       ///< s
  uint8_t charge_state = 0;         ///< MAV_BATTERY_CHARGE_STATE
};

/// An autopilot's message to its operator: pre-arm failures, refusals, EKF state. Texts
/// longer than 50 characters arrive in chunks sharing an id (chunk_seq counts up).
struct Statustext {
  uint8_t severity = 6;  ///< MAV_SEVERITY: 0 emergency … 3 error, 4 warning, 6 info, 7 debug
  std::string text;      ///< up to 50 characters; not NUL-terminated on the wire when full;
                         ///< read: printable ASCII only; unless full, trailing newline and
                         ///< blanks dropped (a full chunk's end may be a blank inside a text)
  uint16_t id = 0;       ///< 0: a message of one chunk (PX4 numbers every text from 0, though)
  uint8_t chunk_seq = 0;
  /// Read: the text filled its 50 characters (no NUL), so a longer text's next chunk may follow.
  bool full = false;
};

/// PX4's camera_trigger module: a picture was triggered (CAMERA_TRIGGER).
struct CameraTrigger {
  uint64_t time_usec = 0;
  uint32_t seq = 0;  ///< image sequence number
};

/// ArduPilot's AP_Camera: a picture was taken, where and how (CAMERA_FEEDBACK).
struct CameraFeedback {
  uint64_t time_usec = 0;
  uint8_t target_system = 0;
  uint8_t cam_idx = 0;
  uint16_t img_idx = 0;
  int32_t lat = 0, lng = 0;             ///< degE7
  float alt_msl = 0, alt_rel = 0;       ///< m
  float roll = 0, pitch = 0, yaw = 0;   ///< deg
  float foc_len = 0;                    ///< mm
  uint8_t flags = 0;                    ///< CAMERA_FEEDBACK_FLAGS
  uint16_t completed_captures = 0;
};

/// The camera protocol's report of one capture, which may have failed (CAMERA_IMAGE_CAPTURED).
struct CameraImageCaptured {
  uint32_t time_boot_ms = 0;
  uint64_t time_utc = 0;  ///< us since the Unix epoch, 0 unknown
  uint8_t camera_id = 0;
  int32_t lat = 0, lon = 0;  ///< degE7
  int32_t alt = 0;           ///< mm above mean sea level
  int32_t relative_alt = 0;  ///< mm above ground
  std::array<float, 4> q{1, 0, 0, 0};  ///< the camera's attitude, w, x, y, z
  int32_t image_index = 0;
  int8_t capture_result = 0;  ///< 1 success, 0 failure
  std::string file_url;       ///< up to 205 characters; read: printable ASCII only
};

/// A vehicle's word that it took a picture, from whichever message its camera sends:
/// CAMERA_TRIGGER (PX4's camera_trigger), CAMERA_FEEDBACK (ArduPilot's AP_Camera) or
/// CAMERA_IMAGE_CAPTURED (the camera protocol; it may report a failed capture).
struct CameraCapture {
  uint32_t message_id = 0;
  int64_t image_index = 0;  ///< the message's sequence or image number
  bool captured = true;     ///< false: CAMERA_IMAGE_CAPTURED with capture_result 0
};

/// A parameter by name (param_index -1) or by index. Names are up to 16 characters.
struct ParamRequestRead {
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  std::string param_id;
  int16_t param_index = -1;  ///< -1: look the parameter up by param_id
};

/// MAV_PARAM_TYPE: the autopilot's type of a parameter. param_value is a float field for every
/// type: ArduPilot converts an integer parameter to a float, PX4 copies its bytes (MAVLink's
/// "bytewise" encoding), so an integer is read by the sender's convention.
namespace param_type {
inline constexpr uint8_t UINT8 = 1, INT8 = 2, UINT16 = 3, INT16 = 4, UINT32 = 5, INT32 = 6, REAL32 = 9;
}

/// One parameter's value, the autopilot's answer to PARAM_REQUEST_READ or PARAM_SET.
struct ParamValue {
  std::string param_id;
  float param_value = 0;
  uint8_t param_type = param_type::REAL32;
  uint16_t param_count = 0;
  uint16_t param_index = 0;
};

/// Sets a parameter; the autopilot answers with PARAM_VALUE (the value it took).
struct ParamSet {
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  std::string param_id;
  float param_value = 0;
  uint8_t param_type = param_type::REAL32;
};

/// MAV_MISSION_TYPE: which of the vehicle's lists a mission-protocol message is about.
namespace mission_type {
inline constexpr uint8_t MISSION = 0, FENCE = 1, RALLY = 2;
}
/// MAV_MISSION_RESULT of a MISSION_ACK (the others are refusals of one kind or another).
namespace mission_result {
inline constexpr uint8_t ACCEPTED = 0, ERROR = 1, UNSUPPORTED = 3, NO_SPACE = 4, INVALID = 5,
                         INVALID_SEQUENCE = 13, DENIED = 14, OPERATION_CANCELLED = 15;
}

/// Starts an upload (from the sender of the list) or answers MISSION_REQUEST_LIST.
struct MissionCount {
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  uint16_t count = 0;
  uint8_t mission_type = mission_type::MISSION;
  uint32_t opaque_id = 0;  ///< the list's version, 0 unknown
};

/// Asks for item `seq`: MISSION_REQUEST_INT, or the older MISSION_REQUEST (`legacy`), which
/// an ArduPilot may still send; the answer is MISSION_ITEM_INT either way.
struct MissionRequest {
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  uint16_t seq = 0;
  uint8_t mission_type = mission_type::MISSION;
  bool legacy = false;  ///< packed as MISSION_REQUEST (40) rather than MISSION_REQUEST_INT (51)
};

/// Asks the vehicle for its list of `mission_type` (a MISSION_COUNT comes back).
struct MissionRequestList {
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  uint8_t mission_type = mission_type::MISSION;
};

/// Ends a transfer: the receiver's verdict on the whole list.
struct MissionAck {
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  uint8_t type = mission_result::ACCEPTED;  ///< MAV_MISSION_RESULT
  uint8_t mission_type = mission_type::MISSION;
  uint32_t opaque_id = 0;
};

/// One item of a list: a MAV_CMD with its parameters, x/y in degE7 for global frames.
struct MissionItemInt {
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  uint16_t seq = 0;
  uint8_t frame = 0;  ///< MAV_FRAME
  uint16_t command = 0;
  uint8_t current = 0;
  uint8_t autocontinue = 0;
  std::array<float, 4> param{};
  int32_t x = 0, y = 0;
  float z = 0;
  uint8_t mission_type = mission_type::MISSION;
};

Message pack(const MissionCount& m);
Message pack(const MissionRequest& m);
Message pack(const MissionRequestList& m);
Message pack(const MissionAck& m);
Message pack(const MissionItemInt& m);
std::optional<MissionCount> unpack_mission_count(const Message& m);
/// MISSION_REQUEST_INT or MISSION_REQUEST (legacy set); nullopt for any other message.
std::optional<MissionRequest> unpack_mission_request(const Message& m);
std::optional<MissionRequestList> unpack_mission_request_list(const Message& m);
std::optional<MissionAck> unpack_mission_ack(const Message& m);
std::optional<MissionItemInt> unpack_mission_item_int(const Message& m);

Message pack(const Heartbeat& m);
Message pack(const ParamRequestRead& m);
Message pack(const ParamValue& m);
Message pack(const ParamSet& m);
Message pack(const SysStatus& m);
Message pack(const Attitude& m);
Message pack(const LocalPositionNed& m);
Message pack(const GlobalPositionInt& m);
Message pack(const HilStateQuaternion& m);
Message pack(const OrbitExecutionStatus& m);
Message pack(const CommandLong& m);
Message pack(const CommandInt& m);
Message pack(const CommandAck& m);
Message pack(const SetPositionTargetLocalNed& m);
Message pack(const ExtendedSysState& m);
Message pack(const BatteryStatus& m);
Message pack(const Statustext& m);
Message pack(const CameraTrigger& m);
Message pack(const CameraFeedback& m);
Message pack(const CameraImageCaptured& m);
/// As the CameraCapture's message_id says, CAMERA_IMAGE_CAPTURED for an id of none of the
/// three; the message's other fields at their defaults.
Message pack(const CameraCapture& m);

/// Gives the vehicle the link's signing key (an all-zero key and timestamp turn signing off).
struct SetupSigning {
  uint8_t target_system = 0;
  uint8_t target_component = 0;
  std::array<uint8_t, 32> secret_key{};
  uint64_t initial_timestamp = 0;  ///< signing clock (signing.h) to start from
};
Message pack(const SetupSigning& m);
std::optional<SetupSigning> unpack_setup_signing(const Message& m);

std::optional<Heartbeat> unpack_heartbeat(const Message& m);
std::optional<ParamRequestRead> unpack_param_request_read(const Message& m);
/// The name keeps only printable ASCII (anything else becomes '?'): it goes into messages.
std::optional<ParamValue> unpack_param_value(const Message& m);
std::optional<ParamSet> unpack_param_set(const Message& m);
std::optional<SysStatus> unpack_sys_status(const Message& m);
std::optional<LocalPositionNed> unpack_local_position_ned(const Message& m);
std::optional<GlobalPositionInt> unpack_global_position_int(const Message& m);
std::optional<HilStateQuaternion> unpack_hil_state_quaternion(const Message& m);
std::optional<Attitude> unpack_attitude(const Message& m);
std::optional<OrbitExecutionStatus> unpack_orbit_execution_status(const Message& m);
std::optional<CommandLong> unpack_command_long(const Message& m);
std::optional<CommandInt> unpack_command_int(const Message& m);
std::optional<CommandAck> unpack_command_ack(const Message& m);
std::optional<SetPositionTargetLocalNed> unpack_set_position_target_local_ned(const Message& m);
std::optional<ExtendedSysState> unpack_extended_sys_state(const Message& m);
std::optional<BatteryStatus> unpack_battery_status(const Message& m);
std::optional<Statustext> unpack_statustext(const Message& m);
std::optional<CameraTrigger> unpack_camera_trigger(const Message& m);
std::optional<CameraFeedback> unpack_camera_feedback(const Message& m);
std::optional<CameraImageCaptured> unpack_camera_image_captured(const Message& m);
/// CAMERA_TRIGGER, CAMERA_FEEDBACK or CAMERA_IMAGE_CAPTURED; nullopt for any other message.
std::optional<CameraCapture> unpack_camera_capture(const Message& m);

}  // namespace eamos::mavlink
