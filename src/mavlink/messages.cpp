#include "mavlink/messages.h"

#include <algorithm>

#include "mavlink/crc.h"

namespace eamos::mavlink {

namespace {

using T = FieldType;

// A field declared after <extensions/>.
FieldDef ext(T type, std::string_view name, uint8_t array_length = 0) {
  return FieldDef{type, name, array_length, true};
}

MessageDef make(uint32_t id, std::string_view name, std::vector<FieldDef> declared) {
  MessageDef def{id, name, wire_order(std::move(declared)), 0, 0, 0};
  int base = 0, total = 0;
  for (const FieldDef& f : def.fields) {
    total += field_size(f);
    if (!f.extension) base += field_size(f);
  }
  def.base_length = static_cast<uint8_t>(base);
  def.length = static_cast<uint8_t>(total);
  def.crc_extra = crc_extra(def.name, def.fields);
  return def;
}

// Fields in common.xml's declaration order.
// long: one table, a message per entry, read against common.xml line by line
std::vector<MessageDef> build_table() {
  std::vector<MessageDef> t;
  t.push_back(make(msg::HEARTBEAT, "HEARTBEAT",
                   {{T::u8, "type"}, {T::u8, "autopilot"}, {T::u8, "base_mode"},
                    {T::u32, "custom_mode"}, {T::u8, "system_status"},
                    {T::u8, "mavlink_version"}}));
  t.push_back(make(msg::SYS_STATUS, "SYS_STATUS",
                   {{T::u32, "onboard_control_sensors_present"},
                    {T::u32, "onboard_control_sensors_enabled"},
                    {T::u32, "onboard_control_sensors_health"}, {T::u16, "load"},
                    {T::u16, "voltage_battery"}, {T::i16, "current_battery"},
                    {T::i8, "battery_remaining"}, {T::u16, "drop_rate_comm"},
                    {T::u16, "errors_comm"}, {T::u16, "errors_count1"},
                    {T::u16, "errors_count2"}, {T::u16, "errors_count3"},
                    {T::u16, "errors_count4"},
                    ext(T::u32, "onboard_control_sensors_present_extended"),
                    ext(T::u32, "onboard_control_sensors_enabled_extended"),
                    ext(T::u32, "onboard_control_sensors_health_extended")}));
  t.push_back(make(msg::PARAM_REQUEST_READ, "PARAM_REQUEST_READ",
                   {{T::u8, "target_system"}, {T::u8, "target_component"},
                    {T::char_, "param_id", 16}, {T::i16, "param_index"}}));
  t.push_back(make(msg::PARAM_VALUE, "PARAM_VALUE",
                   {{T::char_, "param_id", 16}, {T::f32, "param_value"}, {T::u8, "param_type"},
                    {T::u16, "param_count"}, {T::u16, "param_index"}}));
  t.push_back(make(msg::PARAM_SET, "PARAM_SET",
                   {{T::u8, "target_system"}, {T::u8, "target_component"},
                    {T::char_, "param_id", 16}, {T::f32, "param_value"}, {T::u8, "param_type"}}));
  // The vehicle's estimate of its attitude: a test compares its heading with a simulator's truth.
  t.push_back(make(msg::ATTITUDE, "ATTITUDE",
                   {{T::u32, "time_boot_ms"}, {T::f32, "roll"}, {T::f32, "pitch"}, {T::f32, "yaw"},
                    {T::f32, "rollspeed"}, {T::f32, "pitchspeed"}, {T::f32, "yawspeed"}}));
  t.push_back(make(msg::LOCAL_POSITION_NED, "LOCAL_POSITION_NED",
                   {{T::u32, "time_boot_ms"}, {T::f32, "x"}, {T::f32, "y"}, {T::f32, "z"},
                    {T::f32, "vx"}, {T::f32, "vy"}, {T::f32, "vz"}}));
  t.push_back(make(msg::GLOBAL_POSITION_INT, "GLOBAL_POSITION_INT",
                   {{T::u32, "time_boot_ms"}, {T::i32, "lat"}, {T::i32, "lon"},
                    {T::i32, "alt"}, {T::i32, "relative_alt"}, {T::i16, "vx"},
                    {T::i16, "vy"}, {T::i16, "vz"}, {T::u16, "hdg"}}));
  // The mission protocol, used for the fence (mission_type FENCE): upload (COUNT, REQUEST_INT
  // or REQUEST, ITEM_INT, ACK) and read back (REQUEST_LIST, COUNT, REQUEST_INT, ITEM_INT, ACK).
  t.push_back(make(msg::MISSION_REQUEST, "MISSION_REQUEST",
                   {{T::u8, "target_system"}, {T::u8, "target_component"}, {T::u16, "seq"},
                    ext(T::u8, "mission_type")}));
  t.push_back(make(msg::MISSION_REQUEST_LIST, "MISSION_REQUEST_LIST",
                   {{T::u8, "target_system"}, {T::u8, "target_component"}, ext(T::u8, "mission_type")}));
  t.push_back(make(msg::MISSION_COUNT, "MISSION_COUNT",
                   {{T::u8, "target_system"}, {T::u8, "target_component"}, {T::u16, "count"},
                    ext(T::u8, "mission_type"), ext(T::u32, "opaque_id")}));
  t.push_back(make(msg::MISSION_ACK, "MISSION_ACK",
                   {{T::u8, "target_system"}, {T::u8, "target_component"}, {T::u8, "type"},
                    ext(T::u8, "mission_type"), ext(T::u32, "opaque_id")}));
  t.push_back(make(msg::MISSION_REQUEST_INT, "MISSION_REQUEST_INT",
                   {{T::u8, "target_system"}, {T::u8, "target_component"}, {T::u16, "seq"},
                    ext(T::u8, "mission_type")}));
  t.push_back(make(msg::MISSION_ITEM_INT, "MISSION_ITEM_INT",
                   {{T::u8, "target_system"}, {T::u8, "target_component"}, {T::u16, "seq"},
                    {T::u8, "frame"}, {T::u16, "command"}, {T::u8, "current"},
                    {T::u8, "autocontinue"}, {T::f32, "param1"}, {T::f32, "param2"},
                    {T::f32, "param3"}, {T::f32, "param4"}, {T::i32, "x"}, {T::i32, "y"},
                    {T::f32, "z"}, ext(T::u8, "mission_type")}));
  t.push_back(make(msg::COMMAND_INT, "COMMAND_INT",
                   {{T::u8, "target_system"}, {T::u8, "target_component"}, {T::u8, "frame"},
                    {T::u16, "command"}, {T::u8, "current"}, {T::u8, "autocontinue"},
                    {T::f32, "param1"}, {T::f32, "param2"}, {T::f32, "param3"},
                    {T::f32, "param4"}, {T::i32, "x"}, {T::i32, "y"}, {T::f32, "z"}}));
  t.push_back(make(msg::COMMAND_LONG, "COMMAND_LONG",
                   {{T::u8, "target_system"}, {T::u8, "target_component"},
                    {T::u16, "command"}, {T::u8, "confirmation"}, {T::f32, "param1"},
                    {T::f32, "param2"}, {T::f32, "param3"}, {T::f32, "param4"},
                    {T::f32, "param5"}, {T::f32, "param6"}, {T::f32, "param7"}}));
  t.push_back(make(msg::COMMAND_ACK, "COMMAND_ACK",
                   {{T::u16, "command"}, {T::u8, "result"}, ext(T::u8, "progress"),
                    ext(T::i32, "result_param2"), ext(T::u8, "target_system"),
                    ext(T::u8, "target_component")}));
  t.push_back(make(msg::SET_POSITION_TARGET_LOCAL_NED, "SET_POSITION_TARGET_LOCAL_NED",
                   {{T::u32, "time_boot_ms"}, {T::u8, "target_system"},
                    {T::u8, "target_component"}, {T::u8, "coordinate_frame"},
                    {T::u16, "type_mask"}, {T::f32, "x"}, {T::f32, "y"}, {T::f32, "z"},
                    {T::f32, "vx"}, {T::f32, "vy"}, {T::f32, "vz"}, {T::f32, "afx"},
                    {T::f32, "afy"}, {T::f32, "afz"}, {T::f32, "yaw"},
                    {T::f32, "yaw_rate"}}));
  // A picture's confirmations: PX4's camera trigger (camera_trigger module), ArduPilot's
  // camera feedback, and the camera protocol's captured image.
  t.push_back(make(msg::CAMERA_TRIGGER, "CAMERA_TRIGGER", {{T::u64, "time_usec"}, {T::u32, "seq"}}));
  // A simulator's true state (PX4 SIH streams its ground truth under this name): what the
  // vehicle really flew, beside its own estimate, for a test judging a flight.
  t.push_back(make(msg::HIL_STATE_QUATERNION, "HIL_STATE_QUATERNION",
                   {{T::u64, "time_usec"}, {T::f32, "attitude_quaternion", 4}, {T::f32, "rollspeed"},
                    {T::f32, "pitchspeed"}, {T::f32, "yawspeed"}, {T::i32, "lat"}, {T::i32, "lon"},
                    {T::i32, "alt"}, {T::i16, "vx"}, {T::i16, "vy"}, {T::i16, "vz"},
                    {T::u16, "ind_airspeed"}, {T::u16, "true_airspeed"}, {T::i16, "xacc"},
                    {T::i16, "yacc"}, {T::i16, "zacc"}}));
  t.push_back(make(msg::BATTERY_STATUS, "BATTERY_STATUS",
                   {{T::u8, "id"}, {T::u8, "battery_function"}, {T::u8, "type"},
                    {T::i16, "temperature"}, {T::u16, "voltages", 10},
                    {T::i16, "current_battery"}, {T::i32, "current_consumed"},
                    {T::i32, "energy_consumed"}, {T::i8, "battery_remaining"},
                    ext(T::i32, "time_remaining"), ext(T::u8, "charge_state"),
                    ext(T::u16, "voltages_ext", 4), ext(T::u8, "mode"),
                    ext(T::u32, "fault_bitmask")}));
  t.push_back(make(msg::CAMERA_FEEDBACK, "CAMERA_FEEDBACK",
                   {{T::u64, "time_usec"}, {T::u8, "target_system"}, {T::u8, "cam_idx"},
                    {T::u16, "img_idx"}, {T::i32, "lat"}, {T::i32, "lng"}, {T::f32, "alt_msl"},
                    {T::f32, "alt_rel"}, {T::f32, "roll"}, {T::f32, "pitch"}, {T::f32, "yaw"},
                    {T::f32, "foc_len"}, {T::u8, "flags"}, ext(T::u16, "completed_captures")}));
  t.push_back(make(msg::EXTENDED_SYS_STATE, "EXTENDED_SYS_STATE",
                   {{T::u8, "vtol_state"}, {T::u8, "landed_state"}}));
  t.push_back(make(msg::STATUSTEXT, "STATUSTEXT",
                   {{T::u8, "severity"}, {T::char_, "text", 50}, ext(T::u16, "id"),
                    ext(T::u8, "chunk_seq")}));
  t.push_back(make(msg::SETUP_SIGNING, "SETUP_SIGNING",
                   {{T::u8, "target_system"}, {T::u8, "target_component"}, {T::u8, "secret_key", 32},
                    {T::u64, "initial_timestamp"}}));
  t.push_back(make(msg::CAMERA_IMAGE_CAPTURED, "CAMERA_IMAGE_CAPTURED",
                   {{T::u32, "time_boot_ms"}, {T::u64, "time_utc"}, {T::u8, "camera_id"},
                    {T::i32, "lat"}, {T::i32, "lon"}, {T::i32, "alt"}, {T::i32, "relative_alt"},
                    {T::f32, "q", 4}, {T::i32, "image_index"}, {T::i8, "capture_result"},
                    {T::char_, "file_url", 205}}));
  t.push_back(make(msg::ORBIT_EXECUTION_STATUS, "ORBIT_EXECUTION_STATUS",
                   {{T::u64, "time_usec"}, {T::f32, "radius"}, {T::u8, "frame"}, {T::i32, "x"},
                    {T::i32, "y"}, {T::f32, "z"}}));
  return t;
}

}  // namespace

std::vector<FieldDef> wire_order(std::vector<FieldDef> declared) {
  // Extensions keep their place at the end: only the base fields are sorted.
  auto base_end = std::stable_partition(declared.begin(), declared.end(),
                                        [](const FieldDef& f) { return !f.extension; });
  std::stable_sort(declared.begin(), base_end, [](const FieldDef& a, const FieldDef& b) {
    return type_size(a.type) > type_size(b.type);
  });
  int offset = 0;
  for (FieldDef& f : declared) {
    f.offset = static_cast<uint8_t>(offset);
    offset += field_size(f);
  }
  return declared;
}

std::span<const MessageDef> message_table() {
  static const std::vector<MessageDef> table = build_table();
  return table;
}

const MessageDef* find_message(uint32_t id) {
  for (const MessageDef& def : message_table())
    if (def.id == id) return &def;
  return nullptr;
}

const FieldDef* find_field(const MessageDef& def, std::string_view name) {
  for (const FieldDef& f : def.fields)
    if (f.name == name) return &f;
  return nullptr;
}

}  // namespace eamos::mavlink
