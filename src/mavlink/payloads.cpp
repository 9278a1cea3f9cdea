#include "mavlink/payloads.h"

#include <string>

namespace eamos::mavlink {

namespace {

// Every id used below is in the table (the round-trip tests cover each one).
const MessageDef& def_of(uint32_t id) { return *find_message(id); }

std::string param_name(int i) { return "param" + std::to_string(i + 1); }

// Text from the vehicle goes into logs, traces and JSON: anything but printable ASCII (a
// hostile or broken sender's bytes, invalid UTF-8) becomes '?'.
std::string printable(std::string text) {
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
  return text;
}

}  // namespace

Message pack(const Heartbeat& m) {
  FieldWriter w(def_of(msg::HEARTBEAT));
  w.set("type", m.type);
  w.set("autopilot", m.autopilot);
  w.set("base_mode", m.base_mode);
  w.set("custom_mode", m.custom_mode);
  w.set("system_status", m.system_status);
  w.set("mavlink_version", m.mavlink_version);
  return w.take();
}

std::optional<Heartbeat> unpack_heartbeat(const Message& m) {
  if (m.id != msg::HEARTBEAT) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return Heartbeat{r.get<uint8_t>("type"), r.get<uint8_t>("autopilot"),
                   r.get<uint8_t>("base_mode"), r.get<uint32_t>("custom_mode"),
                   r.get<uint8_t>("system_status"), r.get<uint8_t>("mavlink_version")};
}

Message pack(const ParamRequestRead& m) {
  FieldWriter w(def_of(msg::PARAM_REQUEST_READ));
  w.set("target_system", m.target_system);
  w.set("target_component", m.target_component);
  w.set_chars("param_id", m.param_id);
  w.set("param_index", m.param_index);
  return w.take();
}

std::optional<ParamRequestRead> unpack_param_request_read(const Message& m) {
  if (m.id != msg::PARAM_REQUEST_READ) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return ParamRequestRead{r.get<uint8_t>("target_system"), r.get<uint8_t>("target_component"),
                          printable(r.get_chars("param_id")), r.get<int16_t>("param_index")};
}

Message pack(const ParamValue& m) {
  FieldWriter w(def_of(msg::PARAM_VALUE));
  w.set_chars("param_id", m.param_id);
  w.set("param_value", m.param_value);
  w.set("param_type", m.param_type);
  w.set("param_count", m.param_count);
  w.set("param_index", m.param_index);
  return w.take();
}

std::optional<ParamValue> unpack_param_value(const Message& m) {
  if (m.id != msg::PARAM_VALUE) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return ParamValue{printable(r.get_chars("param_id")), r.get<float>("param_value"),
                    r.get<uint8_t>("param_type"), r.get<uint16_t>("param_count"),
                    r.get<uint16_t>("param_index")};
}

Message pack(const ParamSet& m) {
  FieldWriter w(def_of(msg::PARAM_SET));
  w.set("target_system", m.target_system);
  w.set("target_component", m.target_component);
  w.set_chars("param_id", m.param_id);
  w.set("param_value", m.param_value);
  w.set("param_type", m.param_type);
  return w.take();
}

std::optional<ParamSet> unpack_param_set(const Message& m) {
  if (m.id != msg::PARAM_SET) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return ParamSet{r.get<uint8_t>("target_system"), r.get<uint8_t>("target_component"),
                  printable(r.get_chars("param_id")), r.get<float>("param_value"),
                  r.get<uint8_t>("param_type")};
}

Message pack(const SysStatus& m) {
  FieldWriter w(def_of(msg::SYS_STATUS));
  w.set("onboard_control_sensors_present", m.sensors_present);
  w.set("onboard_control_sensors_enabled", m.sensors_enabled);
  w.set("onboard_control_sensors_health", m.sensors_health);
  w.set("load", m.load);
  w.set("voltage_battery", m.voltage_battery);
  w.set("current_battery", m.current_battery);
  w.set("battery_remaining", m.battery_remaining);
  w.set("drop_rate_comm", m.drop_rate_comm);
  w.set("errors_comm", m.errors_comm);
  return w.take();
}

std::optional<SysStatus> unpack_sys_status(const Message& m) {
  if (m.id != msg::SYS_STATUS) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return SysStatus{r.get<uint32_t>("onboard_control_sensors_present"),
                   r.get<uint32_t>("onboard_control_sensors_enabled"),
                   r.get<uint32_t>("onboard_control_sensors_health"),
                   r.get<uint16_t>("load"),
                   r.get<uint16_t>("voltage_battery"),
                   r.get<int16_t>("current_battery"),
                   r.get<int8_t>("battery_remaining"),
                   r.get<uint16_t>("drop_rate_comm"),
                   r.get<uint16_t>("errors_comm")};
}

Message pack(const LocalPositionNed& m) {
  FieldWriter w(def_of(msg::LOCAL_POSITION_NED));
  w.set("time_boot_ms", m.time_boot_ms);
  w.set("x", m.x);
  w.set("y", m.y);
  w.set("z", m.z);
  w.set("vx", m.vx);
  w.set("vy", m.vy);
  w.set("vz", m.vz);
  return w.take();
}

std::optional<LocalPositionNed> unpack_local_position_ned(const Message& m) {
  if (m.id != msg::LOCAL_POSITION_NED) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return LocalPositionNed{r.get<uint32_t>("time_boot_ms"), r.get<float>("x"),
                          r.get<float>("y"), r.get<float>("z"), r.get<float>("vx"),
                          r.get<float>("vy"), r.get<float>("vz")};
}

Message pack(const GlobalPositionInt& m) {
  FieldWriter w(def_of(msg::GLOBAL_POSITION_INT));
  w.set("time_boot_ms", m.time_boot_ms);
  w.set("lat", m.lat);
  w.set("lon", m.lon);
  w.set("alt", m.alt);
  w.set("relative_alt", m.relative_alt);
  w.set("vx", m.vx);
  w.set("vy", m.vy);
  w.set("vz", m.vz);
  w.set("hdg", m.hdg);
  return w.take();
}

std::optional<GlobalPositionInt> unpack_global_position_int(const Message& m) {
  if (m.id != msg::GLOBAL_POSITION_INT) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return GlobalPositionInt{r.get<uint32_t>("time_boot_ms"), r.get<int32_t>("lat"),
                           r.get<int32_t>("lon"), r.get<int32_t>("alt"),
                           r.get<int32_t>("relative_alt"), r.get<int16_t>("vx"),
                           r.get<int16_t>("vy"), r.get<int16_t>("vz"),
                           r.get<uint16_t>("hdg")};
}

Message pack(const HilStateQuaternion& m) {
  FieldWriter w(def_of(msg::HIL_STATE_QUATERNION));
  w.set("time_usec", m.time_usec);
  for (int k = 0; k < 4; ++k) w.set("attitude_quaternion", m.attitude_quaternion[k], k);
  w.set("lat", m.lat);
  w.set("lon", m.lon);
  w.set("alt", m.alt);
  w.set("vx", m.vx);
  w.set("vy", m.vy);
  w.set("vz", m.vz);
  return w.take();
}

std::optional<HilStateQuaternion> unpack_hil_state_quaternion(const Message& m) {
  if (m.id != msg::HIL_STATE_QUATERNION) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  HilStateQuaternion out{r.get<uint64_t>("time_usec"), {}, r.get<int32_t>("lat"), r.get<int32_t>("lon"),
                         r.get<int32_t>("alt"), r.get<int16_t>("vx"), r.get<int16_t>("vy"), r.get<int16_t>("vz")};
  for (int k = 0; k < 4; ++k) out.attitude_quaternion[k] = r.get<float>("attitude_quaternion", k);
  return out;
}

Message pack(const Attitude& m) {
  FieldWriter w(def_of(msg::ATTITUDE));
  w.set("time_boot_ms", m.time_boot_ms);
  w.set("roll", m.roll);
  w.set("pitch", m.pitch);
  w.set("yaw", m.yaw);
  return w.take();
}

std::optional<Attitude> unpack_attitude(const Message& m) {
  if (m.id != msg::ATTITUDE) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return Attitude{r.get<uint32_t>("time_boot_ms"), r.get<float>("roll"), r.get<float>("pitch"), r.get<float>("yaw")};
}

Message pack(const OrbitExecutionStatus& m) {
  FieldWriter w(def_of(msg::ORBIT_EXECUTION_STATUS));
  w.set("time_usec", m.time_usec);
  w.set("radius", m.radius);
  w.set("frame", m.frame);
  w.set("x", m.x);
  w.set("y", m.y);
  w.set("z", m.z);
  return w.take();
}

std::optional<OrbitExecutionStatus> unpack_orbit_execution_status(const Message& m) {
  if (m.id != msg::ORBIT_EXECUTION_STATUS) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return OrbitExecutionStatus{r.get<uint64_t>("time_usec"), r.get<float>("radius"), r.get<uint8_t>("frame"),
                              r.get<int32_t>("x"), r.get<int32_t>("y"), r.get<float>("z")};
}

Message pack(const CommandLong& m) {
  FieldWriter w(def_of(msg::COMMAND_LONG));
  w.set("target_system", m.target_system);
  w.set("target_component", m.target_component);
  w.set("command", m.command);
  w.set("confirmation", m.confirmation);
  for (int i = 0; i < 7; ++i) w.set(param_name(i), m.param[i]);
  return w.take();
}

std::optional<CommandLong> unpack_command_long(const Message& m) {
  if (m.id != msg::COMMAND_LONG) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  CommandLong c{r.get<uint8_t>("target_system"), r.get<uint8_t>("target_component"),
                r.get<uint16_t>("command"), r.get<uint8_t>("confirmation"), {}};
  for (int i = 0; i < 7; ++i) c.param[i] = r.get<float>(param_name(i));
  return c;
}

Message pack(const CommandInt& m) {
  FieldWriter w(def_of(msg::COMMAND_INT));
  w.set("target_system", m.target_system);
  w.set("target_component", m.target_component);
  w.set("frame", m.frame);
  w.set("command", m.command);
  w.set("current", m.current);
  w.set("autocontinue", m.autocontinue);
  for (int i = 0; i < 4; ++i) w.set(param_name(i), m.param[i]);
  w.set("x", m.x);
  w.set("y", m.y);
  w.set("z", m.z);
  return w.take();
}

std::optional<CommandInt> unpack_command_int(const Message& m) {
  if (m.id != msg::COMMAND_INT) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  CommandInt c{r.get<uint8_t>("target_system"), r.get<uint8_t>("target_component"),
               r.get<uint8_t>("frame"), r.get<uint16_t>("command"),
               r.get<uint8_t>("current"), r.get<uint8_t>("autocontinue"), {},
               r.get<int32_t>("x"), r.get<int32_t>("y"), r.get<float>("z")};
  for (int i = 0; i < 4; ++i) c.param[i] = r.get<float>(param_name(i));
  return c;
}

Message pack(const CommandAck& m) {
  FieldWriter w(def_of(msg::COMMAND_ACK));
  w.set("command", m.command);
  w.set("result", m.result);
  w.set("progress", m.progress);
  w.set("result_param2", m.result_param2);
  w.set("target_system", m.target_system);
  w.set("target_component", m.target_component);
  return w.take();
}

std::optional<CommandAck> unpack_command_ack(const Message& m) {
  if (m.id != msg::COMMAND_ACK) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return CommandAck{r.get<uint16_t>("command"), r.get<uint8_t>("result"),
                    r.get<uint8_t>("progress"), r.get<int32_t>("result_param2"),
                    r.get<uint8_t>("target_system"), r.get<uint8_t>("target_component")};
}

Message pack(const SetPositionTargetLocalNed& m) {
  FieldWriter w(def_of(msg::SET_POSITION_TARGET_LOCAL_NED));
  w.set("time_boot_ms", m.time_boot_ms);
  w.set("target_system", m.target_system);
  w.set("target_component", m.target_component);
  w.set("coordinate_frame", m.coordinate_frame);
  w.set("type_mask", m.type_mask);
  w.set("x", m.x);
  w.set("y", m.y);
  w.set("z", m.z);
  w.set("vx", m.vx);
  w.set("vy", m.vy);
  w.set("vz", m.vz);
  w.set("afx", m.afx);
  w.set("afy", m.afy);
  w.set("afz", m.afz);
  w.set("yaw", m.yaw);
  w.set("yaw_rate", m.yaw_rate);
  return w.take();
}

std::optional<SetPositionTargetLocalNed> unpack_set_position_target_local_ned(
    const Message& m) {
  if (m.id != msg::SET_POSITION_TARGET_LOCAL_NED) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return SetPositionTargetLocalNed{
      r.get<uint32_t>("time_boot_ms"), r.get<uint8_t>("target_system"),
      r.get<uint8_t>("target_component"), r.get<uint8_t>("coordinate_frame"),
      r.get<uint16_t>("type_mask"), r.get<float>("x"), r.get<float>("y"), r.get<float>("z"),
      r.get<float>("vx"), r.get<float>("vy"), r.get<float>("vz"), r.get<float>("afx"),
      r.get<float>("afy"), r.get<float>("afz"), r.get<float>("yaw"),
      r.get<float>("yaw_rate")};
}

Message pack(const ExtendedSysState& m) {
  FieldWriter w(def_of(msg::EXTENDED_SYS_STATE));
  w.set("vtol_state", m.vtol_state);
  w.set("landed_state", m.landed_state);
  return w.take();
}

std::optional<ExtendedSysState> unpack_extended_sys_state(const Message& m) {
  if (m.id != msg::EXTENDED_SYS_STATE) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return ExtendedSysState{r.get<uint8_t>("vtol_state"), r.get<uint8_t>("landed_state")};
}

Message pack(const BatteryStatus& m) {
  FieldWriter w(def_of(msg::BATTERY_STATUS));
  w.set("id", m.id);
  w.set("battery_function", m.battery_function);
  w.set("type", m.type);
  w.set("temperature", m.temperature);
  for (int i = 0; i < 10; ++i) w.set("voltages", m.voltages[i], i);
  w.set("current_battery", m.current_battery);
  w.set("current_consumed", m.current_consumed);
  w.set("energy_consumed", m.energy_consumed);
  w.set("battery_remaining", m.battery_remaining);
  w.set("time_remaining", m.time_remaining);
  w.set("charge_state", m.charge_state);
  return w.take();
}

std::optional<BatteryStatus> unpack_battery_status(const Message& m) {
  if (m.id != msg::BATTERY_STATUS) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  BatteryStatus b;
  b.id = r.get<uint8_t>("id");
  b.battery_function = r.get<uint8_t>("battery_function");
  b.type = r.get<uint8_t>("type");
  b.temperature = r.get<int16_t>("temperature");
  for (int i = 0; i < 10; ++i) b.voltages[i] = r.get<uint16_t>("voltages", i);
  b.current_battery = r.get<int16_t>("current_battery");
  b.current_consumed = r.get<int32_t>("current_consumed");
  b.energy_consumed = r.get<int32_t>("energy_consumed");
  b.battery_remaining = r.get<int8_t>("battery_remaining");
  b.time_remaining = r.get<int32_t>("time_remaining");
  b.charge_state = r.get<uint8_t>("charge_state");
  return b;
}

Message pack(const Statustext& m) {
  FieldWriter w(def_of(msg::STATUSTEXT));
  w.set("severity", m.severity);
  w.set_chars("text", m.text);
  w.set("id", m.id);
  w.set("chunk_seq", m.chunk_seq);
  return w.take();
}

std::optional<Statustext> unpack_statustext(const Message& m) {
  if (m.id != msg::STATUSTEXT) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  // PX4 ends a text with a newline: trailing control characters and blanks are no text.
  std::string text = r.get_chars("text");
  while (!text.empty() && static_cast<unsigned char>(text.back()) <= 0x20) text.pop_back();
  return Statustext{r.get<uint8_t>("severity"), printable(text), r.get<uint16_t>("id"),
                    r.get<uint8_t>("chunk_seq")};
}

Message pack(const SetupSigning& m) {
  FieldWriter w(def_of(msg::SETUP_SIGNING));
  w.set("target_system", m.target_system);
  w.set("target_component", m.target_component);
  for (int i = 0; i < 32; ++i) w.set("secret_key", m.secret_key[i], i);
  w.set("initial_timestamp", m.initial_timestamp);
  return w.take();
}

std::optional<SetupSigning> unpack_setup_signing(const Message& m) {
  if (m.id != msg::SETUP_SIGNING) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  SetupSigning s{r.get<uint8_t>("target_system"), r.get<uint8_t>("target_component"), {},
                 r.get<uint64_t>("initial_timestamp")};
  for (int i = 0; i < 32; ++i) s.secret_key[i] = r.get<uint8_t>("secret_key", i);
  return s;
}

Message pack(const CameraCapture& m) {
  FieldWriter w(def_of(m.message_id));
  if (m.message_id == msg::CAMERA_TRIGGER) w.set("seq", static_cast<uint32_t>(m.image_index));
  if (m.message_id == msg::CAMERA_FEEDBACK) w.set("img_idx", static_cast<uint16_t>(m.image_index));
  if (m.message_id == msg::CAMERA_IMAGE_CAPTURED) {
    w.set("image_index", static_cast<int32_t>(m.image_index));
    w.set("capture_result", static_cast<int8_t>(m.captured ? 1 : 0));
  }
  return w.take();
}

std::optional<CameraCapture> unpack_camera_capture(const Message& m) {
  if (m.id != msg::CAMERA_TRIGGER && m.id != msg::CAMERA_FEEDBACK && m.id != msg::CAMERA_IMAGE_CAPTURED)
    return std::nullopt;
  FieldReader r(def_of(m.id), m);
  CameraCapture c;
  c.message_id = m.id;
  if (m.id == msg::CAMERA_TRIGGER) c.image_index = r.get<uint32_t>("seq");
  if (m.id == msg::CAMERA_FEEDBACK) c.image_index = r.get<uint16_t>("img_idx");
  if (m.id == msg::CAMERA_IMAGE_CAPTURED) {
    c.image_index = r.get<int32_t>("image_index");
    c.captured = r.get<int8_t>("capture_result") == 1;
  }
  return c;
}

Message pack(const MissionCount& m) {
  FieldWriter w(def_of(msg::MISSION_COUNT));
  w.set("target_system", m.target_system);
  w.set("target_component", m.target_component);
  w.set("count", m.count);
  w.set("mission_type", m.mission_type);
  w.set("opaque_id", m.opaque_id);
  return w.take();
}

std::optional<MissionCount> unpack_mission_count(const Message& m) {
  if (m.id != msg::MISSION_COUNT) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return MissionCount{r.get<uint8_t>("target_system"), r.get<uint8_t>("target_component"),
                      r.get<uint16_t>("count"), r.get<uint8_t>("mission_type"), r.get<uint32_t>("opaque_id")};
}

Message pack(const MissionRequest& m) {
  FieldWriter w(def_of(m.legacy ? msg::MISSION_REQUEST : msg::MISSION_REQUEST_INT));
  w.set("target_system", m.target_system);
  w.set("target_component", m.target_component);
  w.set("seq", m.seq);
  w.set("mission_type", m.mission_type);
  return w.take();
}

std::optional<MissionRequest> unpack_mission_request(const Message& m) {
  if (m.id != msg::MISSION_REQUEST_INT && m.id != msg::MISSION_REQUEST) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return MissionRequest{r.get<uint8_t>("target_system"), r.get<uint8_t>("target_component"),
                        r.get<uint16_t>("seq"), r.get<uint8_t>("mission_type"), m.id == msg::MISSION_REQUEST};
}

Message pack(const MissionRequestList& m) {
  FieldWriter w(def_of(msg::MISSION_REQUEST_LIST));
  w.set("target_system", m.target_system);
  w.set("target_component", m.target_component);
  w.set("mission_type", m.mission_type);
  return w.take();
}

std::optional<MissionRequestList> unpack_mission_request_list(const Message& m) {
  if (m.id != msg::MISSION_REQUEST_LIST) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return MissionRequestList{r.get<uint8_t>("target_system"), r.get<uint8_t>("target_component"),
                            r.get<uint8_t>("mission_type")};
}

Message pack(const MissionAck& m) {
  FieldWriter w(def_of(msg::MISSION_ACK));
  w.set("target_system", m.target_system);
  w.set("target_component", m.target_component);
  w.set("type", m.type);
  w.set("mission_type", m.mission_type);
  w.set("opaque_id", m.opaque_id);
  return w.take();
}

std::optional<MissionAck> unpack_mission_ack(const Message& m) {
  if (m.id != msg::MISSION_ACK) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  return MissionAck{r.get<uint8_t>("target_system"), r.get<uint8_t>("target_component"),
                    r.get<uint8_t>("type"), r.get<uint8_t>("mission_type"), r.get<uint32_t>("opaque_id")};
}

Message pack(const MissionItemInt& m) {
  FieldWriter w(def_of(msg::MISSION_ITEM_INT));
  w.set("target_system", m.target_system);
  w.set("target_component", m.target_component);
  w.set("seq", m.seq);
  w.set("frame", m.frame);
  w.set("command", m.command);
  w.set("current", m.current);
  w.set("autocontinue", m.autocontinue);
  for (int i = 0; i < 4; ++i) w.set(param_name(i), m.param[i]);
  w.set("x", m.x);
  w.set("y", m.y);
  w.set("z", m.z);
  w.set("mission_type", m.mission_type);
  return w.take();
}

std::optional<MissionItemInt> unpack_mission_item_int(const Message& m) {
  if (m.id != msg::MISSION_ITEM_INT) return std::nullopt;
  FieldReader r(def_of(m.id), m);
  MissionItemInt c{r.get<uint8_t>("target_system"), r.get<uint8_t>("target_component"), r.get<uint16_t>("seq"),
                   r.get<uint8_t>("frame"), r.get<uint16_t>("command"), r.get<uint8_t>("current"),
                   r.get<uint8_t>("autocontinue"), {}, r.get<int32_t>("x"), r.get<int32_t>("y"),
                   r.get<float>("z"), r.get<uint8_t>("mission_type")};
  for (int i = 0; i < 4; ++i) c.param[i] = r.get<float>(param_name(i));
  return c;
}

}  // namespace eamos::mavlink
