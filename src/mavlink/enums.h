#pragma once
// The common.xml enum values the adapter and the simulated vehicle use, named as there, and
// MAV_RESULT in words (a refusal reaches the mission as text).
#include <cstdint>
#include <string>

namespace eamos::mavlink {

namespace cmd {  // MAV_CMD
inline constexpr uint16_t NAV_RETURN_TO_LAUNCH = 20;
inline constexpr uint16_t NAV_LAND = 21;
inline constexpr uint16_t NAV_TAKEOFF = 22;
inline constexpr uint16_t DO_ORBIT = 34;
inline constexpr uint16_t DO_SET_MODE = 176;
inline constexpr uint16_t DO_DIGICAM_CONTROL = 203;
inline constexpr uint16_t COMPONENT_ARM_DISARM = 400;
inline constexpr uint16_t SET_MESSAGE_INTERVAL = 511;
inline constexpr uint16_t REQUEST_MESSAGE = 512;
inline constexpr uint16_t IMAGE_START_CAPTURE = 2000;
inline constexpr uint16_t NAV_FENCE_POLYGON_VERTEX_INCLUSION = 5001;  ///< param1: the polygon's vertex count
}  // namespace cmd

namespace result {  // MAV_RESULT
inline constexpr uint8_t ACCEPTED = 0;
inline constexpr uint8_t TEMPORARILY_REJECTED = 1;
inline constexpr uint8_t DENIED = 2;
inline constexpr uint8_t UNSUPPORTED = 3;
inline constexpr uint8_t FAILED = 4;
inline constexpr uint8_t IN_PROGRESS = 5;
inline constexpr uint8_t CANCELLED = 6;
}  // namespace result

namespace mav_type {  // MAV_TYPE
inline constexpr uint8_t GENERIC = 0;
inline constexpr uint8_t QUADROTOR = 2;
inline constexpr uint8_t GCS = 6;
inline constexpr uint8_t ONBOARD_CONTROLLER = 18;
}  // namespace mav_type

namespace autopilot {  // MAV_AUTOPILOT
inline constexpr uint8_t GENERIC = 0;
inline constexpr uint8_t ARDUPILOTMEGA = 3;
inline constexpr uint8_t INVALID = 8;  ///< not an autopilot (GCS, companion computer)
inline constexpr uint8_t PX4 = 12;
}  // namespace autopilot

namespace mode_flag {  // MAV_MODE_FLAG
inline constexpr uint8_t CUSTOM_MODE_ENABLED = 1;
inline constexpr uint8_t SAFETY_ARMED = 128;
}  // namespace mode_flag

namespace landed {  // MAV_LANDED_STATE
inline constexpr uint8_t UNDEFINED = 0;
inline constexpr uint8_t ON_GROUND = 1;
inline constexpr uint8_t IN_AIR = 2;
inline constexpr uint8_t TAKEOFF = 3;
inline constexpr uint8_t LANDING = 4;
}  // namespace landed

namespace state {  // MAV_STATE
inline constexpr uint8_t STANDBY = 3;
inline constexpr uint8_t ACTIVE = 4;
}  // namespace state

namespace comp {  // MAV_COMPONENT
inline constexpr uint8_t AUTOPILOT1 = 1;
inline constexpr uint8_t ONBOARD_COMPUTER = 191;
}  // namespace comp

/// POSITION_TARGET_TYPEMASK for "position only": velocity, acceleration, yaw and yaw rate
/// ignored (bits 3-8, 10, 11).
inline constexpr uint16_t kPositionOnlyMask = 0x0DF8;
inline constexpr uint16_t kIgnoreYawBit = 0x0400;  ///< bit 10: the setpoint's yaw is not taken
/// ... with the yaw taken: a position and the heading to hold there.
inline constexpr uint16_t kPositionAndYawMask = kPositionOnlyMask & ~kIgnoreYawBit;
inline constexpr uint8_t kFrameLocalNed = 1;  ///< MAV_FRAME_LOCAL_NED
inline constexpr uint8_t kFrameGlobal = 0;    ///< MAV_FRAME_GLOBAL: x, y latitude, longitude
/// MAV_FRAME_GLOBAL, _GLOBAL_RELATIVE_ALT, _GLOBAL_INT, _GLOBAL_RELATIVE_ALT_INT,
/// _GLOBAL_TERRAIN_ALT, _GLOBAL_TERRAIN_ALT_INT: x and y are latitude and longitude.
inline constexpr bool is_global_frame(uint8_t frame) {
  return frame == 0 || frame == 3 || frame == 5 || frame == 6 || frame == 10 || frame == 11;
}

/// PX4's custom_mode: main mode << 16 | sub mode << 24 (PX4's px4_custom_mode.h).
namespace px4 {
inline constexpr uint32_t mode(uint8_t main, uint8_t sub = 0) {
  return uint32_t(main) << 16 | uint32_t(sub) << 24;
}
inline constexpr uint8_t MAIN_POSCTL = 3, MAIN_AUTO = 4, MAIN_OFFBOARD = 6;
inline constexpr uint8_t AUTO_TAKEOFF = 2, AUTO_LOITER = 3, AUTO_RTL = 5, AUTO_LAND = 6;
inline constexpr uint8_t POSCTL_ORBIT = 1;  ///< DO_ORBIT's mode; DO_SET_MODE cannot select it
inline constexpr uint32_t OFFBOARD = mode(MAIN_OFFBOARD);
inline constexpr uint32_t LOITER = mode(MAIN_AUTO, AUTO_LOITER);
inline constexpr uint32_t TAKEOFF = mode(MAIN_AUTO, AUTO_TAKEOFF);
inline constexpr uint32_t LAND = mode(MAIN_AUTO, AUTO_LAND);
inline constexpr uint32_t RTL = mode(MAIN_AUTO, AUTO_RTL);
inline constexpr uint32_t ORBIT = mode(MAIN_POSCTL, POSCTL_ORBIT);
}  // namespace px4

/// "MAV_RESULT_DENIED (denied)" and so on; an unknown value as its number.
std::string result_text(uint8_t mav_result);
/// "MAV_CMD_NAV_TAKEOFF" for the commands above, else "MAV_CMD 1234".
std::string command_name(uint16_t command);

}  // namespace eamos::mavlink
