#include "mavlink/payloads.h"

#include <string>

namespace eamos::mavlink {

namespace {

// Every id used below is in the table (the round-trip tests cover each one).
const MessageDef& def_of(uint32_t id) { return *find_message(id); }

// Text from the vehicle goes into logs, traces and JSON: anything but printable ASCII (a
// hostile or broken sender's bytes, invalid UTF-8) becomes '?'.
std::string printable(std::string text) {
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
  return text;
}

// How a char[N] field is read: made printable at once, or left raw for unpack_statustext,
// which first looks at how the text ends.
enum class Text { printable, raw };

// Pack's side of a message's field list (Layout<M>::fields): struct members into the payload.
class Writer {
 public:
  explicit Writer(uint32_t id) : w_(def_of(id)) {}
  template <typename T>
  void operator()(std::string_view name, const T& value) { w_.set(name, value); }
  template <typename T, size_t N>
  void operator()(std::string_view name, const std::array<T, N>& values) {
    for (size_t i = 0; i < N; ++i) w_.set(name, values[i], static_cast<int>(i));
  }
  void operator()(std::string_view name, const std::string& text, Text = Text::printable) { w_.set_chars(name, text); }
  /// Fields named prefix1, prefix2, ... (COMMAND_LONG's param1..param7), one per element.
  template <typename T, size_t N>
  void numbered(std::string_view prefix, const std::array<T, N>& values) {
    for (size_t i = 0; i < N; ++i) w_.set(std::string(prefix) + std::to_string(i + 1), values[i]);
  }
  Message take() { return w_.take(); }

 private:
  FieldWriter w_;
};

// Unpack's side of the same list: the payload into struct members. Text from the vehicle is
// made printable (it goes into logs, traces and JSON).
class Reader {
 public:
  explicit Reader(const Message& m) : r_(def_of(m.id), m) {}
  template <typename T>
  void operator()(std::string_view name, T& value) { value = r_.get<T>(name); }
  template <typename T, size_t N>
  void operator()(std::string_view name, std::array<T, N>& values) {
    for (size_t i = 0; i < N; ++i) values[i] = r_.get<T>(name, static_cast<int>(i));
  }
  void operator()(std::string_view name, std::string& text, Text mode = Text::printable) {
    text = mode == Text::raw ? r_.get_chars(name) : printable(r_.get_chars(name));
  }
  template <typename T, size_t N>
  void numbered(std::string_view prefix, std::array<T, N>& values) {
    for (size_t i = 0; i < N; ++i) values[i] = r_.get<T>(std::string(prefix) + std::to_string(i + 1));
  }

 private:
  FieldReader r_;
};

// Each message's fields, named once: `fields` is called with a const struct and a Writer by
// pack, and with a fresh struct and a Reader by unpack. A member not listed keeps its default.
template <typename M>
struct Layout;

template <typename M>
Message pack_fields(const M& m) {
  Writer w(Layout<M>::id);
  Layout<M>::fields(m, w);
  return w.take();
}

template <typename M>
std::optional<M> unpack_fields(const Message& m) {
  if (m.id != Layout<M>::id) return std::nullopt;
  M out;
  Reader r(m);
  Layout<M>::fields(out, r);
  return out;
}

template <>
struct Layout<Heartbeat> {
  static constexpr uint32_t id = msg::HEARTBEAT;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("type", m.type);
    v("autopilot", m.autopilot);
    v("base_mode", m.base_mode);
    v("custom_mode", m.custom_mode);
    v("system_status", m.system_status);
    v("mavlink_version", m.mavlink_version);
  }
};

template <>
struct Layout<ParamRequestRead> {
  static constexpr uint32_t id = msg::PARAM_REQUEST_READ;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("target_system", m.target_system);
    v("target_component", m.target_component);
    v("param_id", m.param_id);
    v("param_index", m.param_index);
  }
};

template <>
struct Layout<ParamValue> {
  static constexpr uint32_t id = msg::PARAM_VALUE;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("param_id", m.param_id);
    v("param_value", m.param_value);
    v("param_type", m.param_type);
    v("param_count", m.param_count);
    v("param_index", m.param_index);
  }
};

template <>
struct Layout<ParamSet> {
  static constexpr uint32_t id = msg::PARAM_SET;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("target_system", m.target_system);
    v("target_component", m.target_component);
    v("param_id", m.param_id);
    v("param_value", m.param_value);
    v("param_type", m.param_type);
  }
};

template <>
struct Layout<SysStatus> {
  static constexpr uint32_t id = msg::SYS_STATUS;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("onboard_control_sensors_present", m.sensors_present);
    v("onboard_control_sensors_enabled", m.sensors_enabled);
    v("onboard_control_sensors_health", m.sensors_health);
    v("load", m.load);
    v("voltage_battery", m.voltage_battery);
    v("current_battery", m.current_battery);
    v("battery_remaining", m.battery_remaining);
    v("drop_rate_comm", m.drop_rate_comm);
    v("errors_comm", m.errors_comm);
  }
};

template <>
struct Layout<Attitude> {
  static constexpr uint32_t id = msg::ATTITUDE;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("time_boot_ms", m.time_boot_ms);
    v("roll", m.roll);
    v("pitch", m.pitch);
    v("yaw", m.yaw);
  }
};

template <>
struct Layout<LocalPositionNed> {
  static constexpr uint32_t id = msg::LOCAL_POSITION_NED;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("time_boot_ms", m.time_boot_ms);
    v("x", m.x);
    v("y", m.y);
    v("z", m.z);
    v("vx", m.vx);
    v("vy", m.vy);
    v("vz", m.vz);
  }
};

template <>
struct Layout<GlobalPositionInt> {
  static constexpr uint32_t id = msg::GLOBAL_POSITION_INT;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("time_boot_ms", m.time_boot_ms);
    v("lat", m.lat);
    v("lon", m.lon);
    v("alt", m.alt);
    v("relative_alt", m.relative_alt);
    v("vx", m.vx);
    v("vy", m.vy);
    v("vz", m.vz);
    v("hdg", m.hdg);
  }
};

template <>
struct Layout<HilStateQuaternion> {
  static constexpr uint32_t id = msg::HIL_STATE_QUATERNION;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("time_usec", m.time_usec);
    v("attitude_quaternion", m.attitude_quaternion);
    v("lat", m.lat);
    v("lon", m.lon);
    v("alt", m.alt);
    v("vx", m.vx);
    v("vy", m.vy);
    v("vz", m.vz);
  }
};

template <>
struct Layout<OrbitExecutionStatus> {
  static constexpr uint32_t id = msg::ORBIT_EXECUTION_STATUS;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("time_usec", m.time_usec);
    v("radius", m.radius);
    v("frame", m.frame);
    v("x", m.x);
    v("y", m.y);
    v("z", m.z);
  }
};

template <>
struct Layout<CommandLong> {
  static constexpr uint32_t id = msg::COMMAND_LONG;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("target_system", m.target_system);
    v("target_component", m.target_component);
    v("command", m.command);
    v("confirmation", m.confirmation);
    v.numbered("param", m.param);
  }
};

template <>
struct Layout<CommandInt> {
  static constexpr uint32_t id = msg::COMMAND_INT;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("target_system", m.target_system);
    v("target_component", m.target_component);
    v("frame", m.frame);
    v("command", m.command);
    v("current", m.current);
    v("autocontinue", m.autocontinue);
    v.numbered("param", m.param);
    v("x", m.x);
    v("y", m.y);
    v("z", m.z);
  }
};

template <>
struct Layout<MissionCount> {
  static constexpr uint32_t id = msg::MISSION_COUNT;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("target_system", m.target_system);
    v("target_component", m.target_component);
    v("count", m.count);
    v("mission_type", m.mission_type);
    v("opaque_id", m.opaque_id);
  }
};

template <>
struct Layout<MissionRequestList> {
  static constexpr uint32_t id = msg::MISSION_REQUEST_LIST;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("target_system", m.target_system);
    v("target_component", m.target_component);
    v("mission_type", m.mission_type);
  }
};

template <>
struct Layout<MissionAck> {
  static constexpr uint32_t id = msg::MISSION_ACK;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("target_system", m.target_system);
    v("target_component", m.target_component);
    v("type", m.type);
    v("mission_type", m.mission_type);
    v("opaque_id", m.opaque_id);
  }
};

template <>
struct Layout<MissionItemInt> {
  static constexpr uint32_t id = msg::MISSION_ITEM_INT;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("target_system", m.target_system);
    v("target_component", m.target_component);
    v("seq", m.seq);
    v("frame", m.frame);
    v("command", m.command);
    v("current", m.current);
    v("autocontinue", m.autocontinue);
    v.numbered("param", m.param);
    v("x", m.x);
    v("y", m.y);
    v("z", m.z);
    v("mission_type", m.mission_type);
  }
};

template <typename M, typename V>
void mission_request_fields(M& m, V& v) {
  v("target_system", m.target_system);
  v("target_component", m.target_component);
  v("seq", m.seq);
  v("mission_type", m.mission_type);
}

template <>
struct Layout<CommandAck> {
  static constexpr uint32_t id = msg::COMMAND_ACK;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("command", m.command);
    v("result", m.result);
    v("progress", m.progress);
    v("result_param2", m.result_param2);
    v("target_system", m.target_system);
    v("target_component", m.target_component);
  }
};

template <>
struct Layout<SetPositionTargetLocalNed> {
  static constexpr uint32_t id = msg::SET_POSITION_TARGET_LOCAL_NED;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("time_boot_ms", m.time_boot_ms);
    v("target_system", m.target_system);
    v("target_component", m.target_component);
    v("coordinate_frame", m.coordinate_frame);
    v("type_mask", m.type_mask);
    v("x", m.x);
    v("y", m.y);
    v("z", m.z);
    v("vx", m.vx);
    v("vy", m.vy);
    v("vz", m.vz);
    v("afx", m.afx);
    v("afy", m.afy);
    v("afz", m.afz);
    v("yaw", m.yaw);
    v("yaw_rate", m.yaw_rate);
  }
};

template <>
struct Layout<ExtendedSysState> {
  static constexpr uint32_t id = msg::EXTENDED_SYS_STATE;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("vtol_state", m.vtol_state);
    v("landed_state", m.landed_state);
  }
};

template <>
struct Layout<BatteryStatus> {
  static constexpr uint32_t id = msg::BATTERY_STATUS;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("id", m.id);
    v("battery_function", m.battery_function);
    v("type", m.type);
    v("temperature", m.temperature);
    v("voltages", m.voltages);
    v("current_battery", m.current_battery);
    v("current_consumed", m.current_consumed);
    v("energy_consumed", m.energy_consumed);
    v("battery_remaining", m.battery_remaining);
    v("time_remaining", m.time_remaining);
    v("charge_state", m.charge_state);
  }
};

template <>
struct Layout<Statustext> {
  static constexpr uint32_t id = msg::STATUSTEXT;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("severity", m.severity);
    v("text", m.text, Text::raw);
    v("id", m.id);
    v("chunk_seq", m.chunk_seq);
  }
};

template <>
struct Layout<SetupSigning> {
  static constexpr uint32_t id = msg::SETUP_SIGNING;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("target_system", m.target_system);
    v("target_component", m.target_component);
    v("secret_key", m.secret_key);
    v("initial_timestamp", m.initial_timestamp);
  }
};

template <>
struct Layout<CameraTrigger> {
  static constexpr uint32_t id = msg::CAMERA_TRIGGER;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("time_usec", m.time_usec);
    v("seq", m.seq);
  }
};

template <>
struct Layout<CameraFeedback> {
  static constexpr uint32_t id = msg::CAMERA_FEEDBACK;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("time_usec", m.time_usec);
    v("target_system", m.target_system);
    v("cam_idx", m.cam_idx);
    v("img_idx", m.img_idx);
    v("lat", m.lat);
    v("lng", m.lng);
    v("alt_msl", m.alt_msl);
    v("alt_rel", m.alt_rel);
    v("roll", m.roll);
    v("pitch", m.pitch);
    v("yaw", m.yaw);
    v("foc_len", m.foc_len);
    v("flags", m.flags);
    v("completed_captures", m.completed_captures);
  }
};

template <>
struct Layout<CameraImageCaptured> {
  static constexpr uint32_t id = msg::CAMERA_IMAGE_CAPTURED;
  template <typename M, typename V>
  static void fields(M& m, V& v) {
    v("time_boot_ms", m.time_boot_ms);
    v("time_utc", m.time_utc);
    v("camera_id", m.camera_id);
    v("lat", m.lat);
    v("lon", m.lon);
    v("alt", m.alt);
    v("relative_alt", m.relative_alt);
    v("q", m.q);
    v("image_index", m.image_index);
    v("capture_result", m.capture_result);
    v("file_url", m.file_url);
  }
};
}  // namespace

Message pack(const Heartbeat& m) { return pack_fields(m); }
std::optional<Heartbeat> unpack_heartbeat(const Message& m) { return unpack_fields<Heartbeat>(m); }

Message pack(const ParamRequestRead& m) { return pack_fields(m); }
std::optional<ParamRequestRead> unpack_param_request_read(const Message& m) { return unpack_fields<ParamRequestRead>(m); }

Message pack(const ParamValue& m) { return pack_fields(m); }
std::optional<ParamValue> unpack_param_value(const Message& m) { return unpack_fields<ParamValue>(m); }

Message pack(const ParamSet& m) { return pack_fields(m); }
std::optional<ParamSet> unpack_param_set(const Message& m) { return unpack_fields<ParamSet>(m); }

Message pack(const SysStatus& m) { return pack_fields(m); }
std::optional<SysStatus> unpack_sys_status(const Message& m) { return unpack_fields<SysStatus>(m); }

Message pack(const Attitude& m) { return pack_fields(m); }
std::optional<Attitude> unpack_attitude(const Message& m) { return unpack_fields<Attitude>(m); }

Message pack(const LocalPositionNed& m) { return pack_fields(m); }
std::optional<LocalPositionNed> unpack_local_position_ned(const Message& m) { return unpack_fields<LocalPositionNed>(m); }

Message pack(const GlobalPositionInt& m) { return pack_fields(m); }
std::optional<GlobalPositionInt> unpack_global_position_int(const Message& m) { return unpack_fields<GlobalPositionInt>(m); }

Message pack(const HilStateQuaternion& m) { return pack_fields(m); }
std::optional<HilStateQuaternion> unpack_hil_state_quaternion(const Message& m) { return unpack_fields<HilStateQuaternion>(m); }

Message pack(const OrbitExecutionStatus& m) { return pack_fields(m); }
std::optional<OrbitExecutionStatus> unpack_orbit_execution_status(const Message& m) { return unpack_fields<OrbitExecutionStatus>(m); }

Message pack(const CommandLong& m) { return pack_fields(m); }
std::optional<CommandLong> unpack_command_long(const Message& m) { return unpack_fields<CommandLong>(m); }

Message pack(const CommandInt& m) { return pack_fields(m); }
std::optional<CommandInt> unpack_command_int(const Message& m) { return unpack_fields<CommandInt>(m); }

Message pack(const CommandAck& m) { return pack_fields(m); }
std::optional<CommandAck> unpack_command_ack(const Message& m) { return unpack_fields<CommandAck>(m); }

Message pack(const SetPositionTargetLocalNed& m) { return pack_fields(m); }
std::optional<SetPositionTargetLocalNed> unpack_set_position_target_local_ned(const Message& m) { return unpack_fields<SetPositionTargetLocalNed>(m); }

Message pack(const ExtendedSysState& m) { return pack_fields(m); }
std::optional<ExtendedSysState> unpack_extended_sys_state(const Message& m) { return unpack_fields<ExtendedSysState>(m); }

Message pack(const BatteryStatus& m) { return pack_fields(m); }
std::optional<BatteryStatus> unpack_battery_status(const Message& m) { return unpack_fields<BatteryStatus>(m); }

Message pack(const Statustext& m) { return pack_fields(m); }
std::optional<Statustext> unpack_statustext(const Message& m) {
  constexpr std::size_t kStatustextChars = 50;
  std::optional<Statustext> t = unpack_fields<Statustext>(m);
  if (!t) return t;
  t->full = t->text.size() == kStatustextChars;
  // PX4 ends a text with a newline, which is no text, also when it fills the chunk; a full
  // chunk's last blank may be the blank between two words of a longer text, so it stays.
  auto trailing = [&](unsigned char c) { return c < 0x20 || (c == ' ' && !t->full); };
  while (!t->text.empty() && trailing(static_cast<unsigned char>(t->text.back()))) t->text.pop_back();
  t->text = printable(std::move(t->text));
  return t;
}

Message pack(const SetupSigning& m) { return pack_fields(m); }
std::optional<SetupSigning> unpack_setup_signing(const Message& m) { return unpack_fields<SetupSigning>(m); }

Message pack(const CameraTrigger& m) { return pack_fields(m); }
std::optional<CameraTrigger> unpack_camera_trigger(const Message& m) { return unpack_fields<CameraTrigger>(m); }

Message pack(const CameraFeedback& m) { return pack_fields(m); }
std::optional<CameraFeedback> unpack_camera_feedback(const Message& m) { return unpack_fields<CameraFeedback>(m); }

Message pack(const CameraImageCaptured& m) { return pack_fields(m); }
std::optional<CameraImageCaptured> unpack_camera_image_captured(const Message& m) {
  return unpack_fields<CameraImageCaptured>(m);
}

// The image numbers are cast to each message's field type: a sequence past it wraps as the
// vehicle's own counter does.
Message pack(const CameraCapture& m) {
  if (m.message_id == msg::CAMERA_TRIGGER)
    return pack(CameraTrigger{.seq = static_cast<uint32_t>(m.image_index)});
  if (m.message_id == msg::CAMERA_FEEDBACK)
    return pack(CameraFeedback{.img_idx = static_cast<uint16_t>(m.image_index)});
  CameraImageCaptured c;
  c.image_index = static_cast<int32_t>(m.image_index);
  c.capture_result = m.captured ? 1 : 0;
  return pack(c);
}

std::optional<CameraCapture> unpack_camera_capture(const Message& m) {
  if (auto t = unpack_camera_trigger(m)) return CameraCapture{m.id, t->seq, true};
  if (auto f = unpack_camera_feedback(m)) return CameraCapture{m.id, f->img_idx, true};
  if (auto c = unpack_camera_image_captured(m))
    return CameraCapture{m.id, c->image_index, c->capture_result == 1};
  return std::nullopt;
}

Message pack(const MissionCount& m) { return pack_fields(m); }
std::optional<MissionCount> unpack_mission_count(const Message& m) { return unpack_fields<MissionCount>(m); }

Message pack(const MissionRequestList& m) { return pack_fields(m); }
std::optional<MissionRequestList> unpack_mission_request_list(const Message& m) {
  return unpack_fields<MissionRequestList>(m);
}

Message pack(const MissionAck& m) { return pack_fields(m); }
std::optional<MissionAck> unpack_mission_ack(const Message& m) { return unpack_fields<MissionAck>(m); }

Message pack(const MissionItemInt& m) { return pack_fields(m); }
std::optional<MissionItemInt> unpack_mission_item_int(const Message& m) { return unpack_fields<MissionItemInt>(m); }

// MISSION_REQUEST and MISSION_REQUEST_INT share their fields; `legacy` says which id.
Message pack(const MissionRequest& m) {
  Writer w(m.legacy ? msg::MISSION_REQUEST : msg::MISSION_REQUEST_INT);
  mission_request_fields(m, w);
  return w.take();
}

std::optional<MissionRequest> unpack_mission_request(const Message& m) {
  if (m.id != msg::MISSION_REQUEST_INT && m.id != msg::MISSION_REQUEST) return std::nullopt;
  MissionRequest out;
  Reader r(m);
  mission_request_fields(out, r);
  out.legacy = m.id == msg::MISSION_REQUEST;
  return out;
}

}  // namespace eamos::mavlink
