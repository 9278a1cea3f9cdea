#include "transport/wire_convert.h"

#include <cmath>
#include <cstring>

namespace eamos::transport {

namespace {

char* borrow(const std::string& s) { return const_cast<char*>(s.c_str()); }

/// True when the `n` bytes at `s` are well-formed UTF-8 (no overlong forms, surrogates
/// or code points past U+10FFFF): names and reasons end up in logs and JSON traces.
bool is_utf8(const unsigned char* s, std::size_t n) {
  for (std::size_t i = 0; i < n;) {
    unsigned char c = s[i];
    std::size_t len = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    if (len == 0 || i + len > n) return false;
    std::uint32_t cp = len == 1 ? c : len == 2 ? c & 0x1F : len == 3 ? c & 0x0F : c & 0x07;
    for (std::size_t k = 1; k < len; ++k) {
      if ((s[i + k] & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (s[i + k] & 0x3F);
    }
    static const std::uint32_t kMin[] = {0, 0, 0x80, 0x800, 0x10000};
    if (cp < kMin[len] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += len;
  }
  return true;
}

/// Checks one received sample field by field; the first broken rule is kept in `why`.
class Check {
 public:
  Check(const WireLimits& limits, std::string& why) : limits_(limits), why_(why) {}

  bool ok() const { return ok_; }

  /// A drone index of the mission (`ground`: -1, the ground process, allowed too).
  void drone(const char* field, long long v, bool ground = false) {
    long long count = limits_.drones > 0 ? limits_.drones : kMaxWireDrones;
    if (v >= count || v < (ground ? -1 : 0))
      fail(std::string(field) + " " + std::to_string(v) + " is not a drone of the mission (" +
           std::to_string(count) + " drones)");
  }
  void at_least(const char* field, long long v, long long lo) {
    if (v < lo) fail(std::string(field) + " " + std::to_string(v) + " is below " + std::to_string(lo));
  }
  void in_range(const char* field, long long v, long long lo, long long hi) {
    if (v < lo || v > hi)
      fail(std::string(field) + " " + std::to_string(v) + " is outside " + std::to_string(lo) + " to " + std::to_string(hi));
  }
  void positive(const char* field, double v) {
    if (!(v > 0)) fail(std::string(field) + " is not positive");
  }
  void one_of(const char* field, long long v, long long count) {
    if (v < 0 || v >= count) fail(std::string(field) + " " + std::to_string(v) + " is not a known value");
  }
  void within(const char* field, double v, double bound) {
    if (!(std::abs(v) <= bound)) fail(std::string(field) + " is not between -" + std::to_string(bound) + " and " + std::to_string(bound));
  }
  void finite(const char* field, double v) {
    if (!std::isfinite(v)) fail(std::string(field) + " is " + (std::isnan(v) ? "NaN" : "infinite"));
  }
  void count(const char* field, std::size_t n, std::size_t max) {
    if (n > max) fail(std::string(field) + " holds " + std::to_string(n) + " entries, more than " + std::to_string(max));
  }
  /// A copy of a received string, "" (and the sample refused) when it is too long or not
  /// UTF-8. strnlen: the string is never read further than its limit.
  std::string text(const char* field, const char* s, std::size_t max) {
    if (!s) return {};
    std::size_t n = strnlen(s, max + 1);
    if (n > max) {
      fail(std::string(field) + " is longer than " + std::to_string(max) + " bytes");
      return {};
    }
    if (!is_utf8(reinterpret_cast<const unsigned char*>(s), n)) {
      fail(std::string(field) + " is not UTF-8");
      return {};
    }
    return std::string(s, n);
  }

 private:
  void fail(std::string why) {
    if (ok_) why_ = std::move(why);
    ok_ = false;
  }

  const WireLimits& limits_;
  std::string& why_;
  bool ok_ = true;
};

void state_to_wire(const mid::DroneState& s, double& t, double& x, double& y, double& z, double& battery,
                   bool& armed, bool& landed, int32_t& pictures) {
  t = s.t, x = s.x, y = s.y, z = s.z, battery = s.battery;
  armed = s.armed, landed = s.landed, pictures = s.pictures;
}

template <typename W>
mid::DroneState state_from_wire(const W& w, Check& check) {
  check.finite("t", w.t);
  check.finite("x", w.x);
  check.finite("y", w.y);
  check.finite("z", w.z);
  check.finite("battery", w.battery);
  check.at_least("pictures", w.pictures, 0);
  mid::DroneState s;
  s.t = w.t, s.x = w.x, s.y = w.y, s.z = w.z, s.battery = w.battery;
  s.armed = w.armed, s.landed = w.landed, s.pictures = w.pictures;
  return s;
}

constexpr long long kBranches = static_cast<long long>(graph::Branch::continue_) + 1;

/// An IDL enum field as the number the sender put there. A C enum can hold any value of
/// its 32 bits, and reading one outside the enumeration as the C++ enum type is undefined,
/// so the field's bytes are read as an integer and checked before any cast.
template <typename Enum>
uint32_t raw_enum(const Enum& e) {
  static_assert(sizeof(Enum) == sizeof(uint32_t), "IDL enums are 32 bits on the wire");
  uint32_t v;
  std::memcpy(&v, &e, sizeof v);
  return v;
}

}  // namespace

const char* lifecycle_name(LifecycleKind k) {
  switch (k) {
    case LifecycleKind::ready: return "ready";
    case LifecycleKind::start: return "start";
    case LifecycleKind::abort: return "abort";
    case LifecycleKind::finished: return "finished";
    case LifecycleKind::refused: return "refused";
  }
  return "?";
}

const char* phase_name(Phase p) {
  switch (p) {
    case Phase::waiting: return "waiting";
    case Phase::running: return "running";
    case Phase::completed: return "completed";
    case Phase::failed: return "failed";
    case Phase::failsafe: return "failsafe";
  }
  return "?";
}

eamos_wire_Trigger to_wire(const TriggerSample& s) {
  const dex::Message& m = s.message;
  eamos_wire_Trigger w{};
  w.mission_hash = borrow(m.mission_hash);
  w.run_id = s.run_id;
  w.from = m.from;
  w.to = s.to;
  w.seq = s.seq;
  w.kind = m.kind == dex::Message::Kind::cancel    ? eamos_wire_TRIGGER_CANCEL
           : m.kind == dex::Message::Kind::arrived ? eamos_wire_TRIGGER_ARRIVED
                                                   : eamos_wire_TRIGGER_ENDED;
  w.meg = m.meg;
  w.branch = static_cast<int32_t>(m.branch);
  w.scope = m.scope;
  w.epoch = m.epoch;
  w.body_epoch = m.body_epoch;
  w.sent = m.sent;
  return w;
}

bool from_wire(const eamos_wire_Trigger& w, const WireLimits& limits, TriggerSample& s, std::string& why) {
  Check check(limits, why);
  s = {};
  s.run_id = w.run_id;
  s.seq = w.seq;
  dex::Message& m = s.message;
  uint32_t kind = raw_enum(w.kind);
  check.one_of("kind", kind, 3);
  m.kind = kind == eamos_wire_TRIGGER_CANCEL    ? dex::Message::Kind::cancel
           : kind == eamos_wire_TRIGGER_ARRIVED ? dex::Message::Kind::arrived
                                                : dex::Message::Kind::ended;
  // An arrival goes to every drone at once (kEveryDrone), anything else to one.
  check.drone("to", w.to, m.kind == dex::Message::Kind::arrived);
  s.to = w.to;
  m.mission_hash = check.text("mission_hash", w.mission_hash, kMaxWireHash);
  check.drone("from", w.from);
  m.from = w.from;
  check.at_least("meg", w.meg, 0);
  m.meg = w.meg;
  check.one_of("branch", w.branch, kBranches);
  if (check.ok()) m.branch = static_cast<graph::Branch>(w.branch);
  check.at_least("scope", w.scope, -1);
  m.scope = w.scope;
  check.at_least("epoch", w.epoch, 0);
  m.epoch = w.epoch;
  check.at_least("body_epoch", w.body_epoch, 0);
  m.body_epoch = w.body_epoch;
  check.finite("sent", w.sent);
  m.sent = w.sent;
  return check.ok();
}

void to_wire(const TelemetrySample& s, TelemetryOut& out) {
  const dex::Telemetry& t = s.telemetry;
  out.sensors.clear();
  for (const auto& [name, value] : t.state.sensors) out.sensors.push_back({borrow(name), value});
  eamos_wire_Telemetry& w = out.c;
  w = {};
  w.mission_hash = borrow(t.mission_hash);
  w.from = t.from;
  w.run_id = s.run_id;
  state_to_wire(t.state, w.t, w.x, w.y, w.z, w.battery, w.armed, w.landed, w.pictures);
  w.heading = std::isfinite(t.state.heading) ? t.state.heading : -1.0;
  w.mode = borrow(t.state.mode);
  w.sensors._length = w.sensors._maximum = static_cast<uint32_t>(out.sensors.size());
  w.sensors._buffer = out.sensors.data();
  w.sensors._release = false;
}

bool from_wire(const eamos_wire_Telemetry& w, const WireLimits& limits, TelemetrySample& s, std::string& why) {
  Check check(limits, why);
  s = {};
  s.run_id = w.run_id;
  s.telemetry.mission_hash = check.text("mission_hash", w.mission_hash, kMaxWireHash);
  check.drone("from", w.from);
  s.telemetry.from = w.from;
  s.telemetry.state = state_from_wire(w, check);
  // Heading and mode are only shown to people: an unusable heading is "unknown", not a fault.
  if (std::isfinite(w.heading) && w.heading >= 0 && w.heading < 360) s.telemetry.state.heading = w.heading;
  s.telemetry.state.mode = check.text("mode", w.mode, kMaxWireName);
  check.count("sensors", w.sensors._length, kMaxWireSensors);
  for (uint32_t i = 0; check.ok() && i < w.sensors._length; ++i) {
    std::string name = check.text("sensor name", w.sensors._buffer[i].name, kMaxWireName);
    check.finite("sensor value", w.sensors._buffer[i].value);
    s.telemetry.state.sensors[name] = w.sensors._buffer[i].value;
  }
  return check.ok();
}

eamos_wire_Lifecycle to_wire(const LifecycleSample& s) {
  eamos_wire_Lifecycle w{};
  w.mission_hash = borrow(s.mission_hash);
  w.drone = s.drone;
  w.kind = static_cast<eamos_wire_LifecycleKind>(s.kind);
  w.run_id = s.run_id;
  w.nonce = s.nonce;
  w.launch_id = s.launch_id;
  w.start_at_ns = s.start_at_ns;
  w.speed = s.speed;
  w.t = s.t;
  w.nonces._length = w.nonces._maximum = static_cast<uint32_t>(s.nonces.size());
  w.nonces._buffer = const_cast<uint64_t*>(s.nonces.data());
  w.nonces._release = false;
  static const std::string empty;
  w.reason = borrow(s.reason);
  w.failed_drone = borrow(s.failure ? s.failure->drone : empty);
  w.failed_action = borrow(s.failure ? s.failure->action : empty);
  w.failed_line = s.failure ? s.failure->line : 0;
  w.failed_kind = s.failure ? static_cast<int32_t>(s.failure->kind) : 0;
  w.failed_detail = borrow(s.failure ? s.failure->detail : empty);
  w.has_fix = s.fix.has_value();
  w.fix_lat = s.fix ? s.fix->lat_deg : 0.0;
  w.fix_lon = s.fix ? s.fix->lon_deg : 0.0;
  w.home_x = s.home_x;
  w.home_y = s.home_y;
  w.home_tolerance = s.home_tolerance;
  return w;
}

bool from_wire(const eamos_wire_Lifecycle& w, const WireLimits& limits, LifecycleSample& s, std::string& why) {
  Check check(limits, why);
  s = {};
  s.mission_hash = check.text("mission_hash", w.mission_hash, kMaxWireHash);
  check.drone("drone", w.drone, true);
  s.drone = w.drone;
  uint32_t kind = raw_enum(w.kind);
  check.one_of("kind", kind, 5);
  if (check.ok()) s.kind = static_cast<LifecycleKind>(kind);
  s.run_id = w.run_id;
  s.nonce = w.nonce;
  s.launch_id = w.launch_id;
  s.start_at_ns = w.start_at_ns;
  check.finite("speed", w.speed);
  check.positive("speed", w.speed);
  s.speed = w.speed;
  check.finite("t", w.t);
  s.t = w.t;
  check.count("nonces", w.nonces._length, limits.drones > 0 ? limits.drones : kMaxWireDrones);
  if (check.ok()) s.nonces.assign(w.nonces._buffer, w.nonces._buffer + w.nonces._length);
  s.reason = check.text("reason", w.reason, kMaxWireText);
  std::string failed_drone = check.text("failed_drone", w.failed_drone, kMaxWireName);
  std::string failed_action = check.text("failed_action", w.failed_action, kMaxWireName);
  check.at_least("failed_line", w.failed_line, 0);
  check.one_of("failed_kind", w.failed_kind, static_cast<long long>(mid::FailureReason::pilot_took_over) + 1);
  std::string failed_detail = check.text("failed_detail", w.failed_detail, kMaxWireText);
  if (!failed_drone.empty() && check.ok())
    s.failure = dex::Failure{failed_drone, failed_action, w.failed_line, s.reason,
                             static_cast<mid::FailureReason>(w.failed_kind), failed_detail};
  check.within("fix_lat", w.fix_lat, 90.0);
  check.within("fix_lon", w.fix_lon, 180.0);
  check.within("home_x", w.home_x, 1e7);
  check.within("home_y", w.home_y, 1e7);
  check.within("home_tolerance", w.home_tolerance, 1e7);
  if (w.has_fix && check.ok()) s.fix = mid::GlobalFix{w.fix_lat, w.fix_lon};
  s.home_x = w.home_x;
  s.home_y = w.home_y;
  s.home_tolerance = w.home_tolerance > 0 ? w.home_tolerance : fleet::kDefaultHomeToleranceM;
  return check.ok();
}

eamos_wire_Status to_wire(const StatusSample& s) {
  eamos_wire_Status w{};
  w.mission_hash = borrow(s.mission_hash);
  w.drone = s.drone;
  w.run_id = s.run_id;
  w.nonce = s.nonce;
  w.phase = static_cast<eamos_wire_Phase>(s.phase);
  w.busy = s.busy;
  w.end_reached = s.end_reached;
  w.sent = s.sent;
  w.received = s.received;
  w.activations = s.activations;
  w.wave = s.wave;
  w.since = s.since;
  w.heard = s.heard;
  state_to_wire(s.state, w.t, w.x, w.y, w.z, w.battery, w.armed, w.landed, w.pictures);
  return w;
}

bool from_wire(const eamos_wire_Status& w, const WireLimits& limits, StatusSample& s, std::string& why) {
  Check check(limits, why);
  s = {};
  s.mission_hash = check.text("mission_hash", w.mission_hash, kMaxWireHash);
  check.drone("drone", w.drone);
  s.drone = w.drone;
  s.run_id = w.run_id;
  s.nonce = w.nonce;
  uint32_t phase = raw_enum(w.phase);
  check.one_of("phase", phase, 5);
  if (check.ok()) s.phase = static_cast<Phase>(phase);
  s.busy = w.busy;
  s.end_reached = w.end_reached;
  s.sent = w.sent;
  s.received = w.received;
  s.activations = w.activations;
  s.wave = w.wave;
  check.finite("since", w.since);
  s.since = w.since;
  check.in_range("heard", w.heard, 0, limits.drones > 0 ? limits.drones : kMaxWireDrones);
  s.heard = w.heard;
  s.state = state_from_wire(w, check);
  return check.ok();
}

eamos_wire_TraceRecord to_wire(const TraceSample& s) {
  const dex::TraceEvent& e = s.event;
  eamos_wire_TraceRecord w{};
  w.mission_hash = borrow(s.mission_hash);
  w.run_id = s.run_id;
  w.drone = s.drone;
  w.seq = s.seq;
  w.t = e.t;
  w.event = borrow(e.event);
  w.name = borrow(e.name);
  w.line = e.line;
  w.text = borrow(e.text);
  w.outcome = borrow(e.outcome);
  w.value = e.value ? (*e.value ? 1 : 0) : -1;
  // A give-way's distance travels in `reading` and its other drone in `to`: the wire type
  // stays as it is (dex::is_separation_event).
  const std::optional<double>& number = dex::is_separation_event(e.event) ? e.distance : e.reading;
  w.has_reading = number.has_value();
  w.reading = number.value_or(0.0);
  w.reason = borrow(e.reason);
  w.failure = borrow(e.failure);
  w.detail = borrow(e.detail);
  w.node = e.node;
  w.instance = e.instance;
  w.kind = borrow(e.kind);
  w.branch = borrow(e.branch);
  w.from = e.from;
  w.to = e.to;
  w.sent = e.sent;
  return w;
}

bool from_wire(const eamos_wire_TraceRecord& w, const WireLimits& limits, TraceSample& s, std::string& why) {
  Check check(limits, why);
  s = {};
  s.mission_hash = check.text("mission_hash", w.mission_hash, kMaxWireHash);
  s.run_id = w.run_id;
  check.drone("drone", w.drone);
  s.drone = w.drone;
  s.seq = w.seq;
  dex::TraceEvent& e = s.event;
  check.finite("t", w.t);
  e.t = w.t;
  e.event = check.text("event", w.event, kMaxWireName);
  e.name = check.text("name", w.name, kMaxWireName);
  e.line = w.line;
  check.at_least("line", w.line, 0);
  e.text = check.text("text", w.text, kMaxWireText);
  e.outcome = check.text("outcome", w.outcome, kMaxWireName);
  check.in_range("value", w.value, -1, 1);
  if (w.value >= 0) e.value = w.value == 1;
  if (w.has_reading) {
    check.finite("reading", w.reading);
    e.reading = w.reading;
  }
  e.reason = check.text("reason", w.reason, kMaxWireText);
  e.failure = check.text("failure", w.failure, kMaxWireName);
  e.detail = check.text("detail", w.detail, kMaxWireText);
  check.at_least("node", w.node, -1);
  e.node = w.node;
  check.at_least("instance", w.instance, -1);
  e.instance = w.instance;
  e.kind = check.text("kind", w.kind, kMaxWireName);
  e.branch = check.text("branch", w.branch, kMaxWireName);
  if (e.event == "message") {
    check.drone("from", w.from);
    check.drone("to", w.to);
    check.finite("sent", w.sent);
  }
  if (dex::is_separation_event(e.event)) {
    check.drone("to", w.to);
    e.distance = e.reading;
    e.reading.reset();
  }
  e.from = w.from;
  e.to = w.to;
  e.sent = w.sent;
  return check.ok();
}

}  // namespace eamos::transport
