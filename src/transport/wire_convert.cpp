#include "transport/wire_convert.h"

namespace eamos::transport {

namespace {

char* borrow(const std::string& s) { return const_cast<char*>(s.c_str()); }
std::string copy(const char* s) { return s ? std::string(s) : std::string(); }

void state_to_wire(const mid::DroneState& s, double& t, double& x, double& y, double& z, double& battery,
                   bool& armed, bool& landed, int32_t& pictures) {
  t = s.t, x = s.x, y = s.y, z = s.z, battery = s.battery;
  armed = s.armed, landed = s.landed, pictures = s.pictures;
}

template <typename W>
mid::DroneState state_from_wire(const W& w) {
  mid::DroneState s;
  s.t = w.t, s.x = w.x, s.y = w.y, s.z = w.z, s.battery = w.battery;
  s.armed = w.armed, s.landed = w.landed, s.pictures = w.pictures;
  return s;
}

}  // namespace

const char* lifecycle_name(LifecycleKind k) {
  switch (k) {
    case LifecycleKind::ready: return "ready";
    case LifecycleKind::start: return "start";
    case LifecycleKind::abort: return "abort";
    case LifecycleKind::finished: return "finished";
  }
  return "?";
}

const char* phase_name(Phase p) {
  switch (p) {
    case Phase::waiting: return "waiting";
    case Phase::running: return "running";
    case Phase::completed: return "completed";
    case Phase::failed: return "failed";
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
  w.kind = m.kind == dex::Message::Kind::cancel ? eamos_wire_TRIGGER_CANCEL : eamos_wire_TRIGGER_ENDED;
  w.meg = m.meg;
  w.branch = static_cast<int32_t>(m.branch);
  w.scope = m.scope;
  w.epoch = m.epoch;
  w.body_epoch = m.body_epoch;
  return w;
}

TriggerSample from_wire(const eamos_wire_Trigger& w) {
  TriggerSample s;
  s.run_id = w.run_id;
  s.to = w.to;
  s.seq = w.seq;
  dex::Message& m = s.message;
  m.kind = w.kind == eamos_wire_TRIGGER_CANCEL ? dex::Message::Kind::cancel : dex::Message::Kind::ended;
  m.mission_hash = copy(w.mission_hash);
  m.from = w.from;
  m.meg = w.meg;
  m.branch = static_cast<graph::Branch>(w.branch);
  m.scope = w.scope;
  m.epoch = w.epoch;
  m.body_epoch = w.body_epoch;
  return s;
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
  w.sensors._length = w.sensors._maximum = static_cast<uint32_t>(out.sensors.size());
  w.sensors._buffer = out.sensors.data();
  w.sensors._release = false;
}

TelemetrySample from_wire(const eamos_wire_Telemetry& w) {
  TelemetrySample s;
  s.run_id = w.run_id;
  s.telemetry.mission_hash = copy(w.mission_hash);
  s.telemetry.from = w.from;
  s.telemetry.state = state_from_wire(w);
  for (uint32_t i = 0; i < w.sensors._length; ++i)
    s.telemetry.state.sensors[copy(w.sensors._buffer[i].name)] = w.sensors._buffer[i].value;
  return s;
}

eamos_wire_Lifecycle to_wire(const LifecycleSample& s) {
  eamos_wire_Lifecycle w{};
  w.mission_hash = borrow(s.mission_hash);
  w.drone = s.drone;
  w.kind = static_cast<eamos_wire_LifecycleKind>(s.kind);
  w.run_id = s.run_id;
  w.nonce = s.nonce;
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
  return w;
}

LifecycleSample from_wire(const eamos_wire_Lifecycle& w) {
  LifecycleSample s;
  s.mission_hash = copy(w.mission_hash);
  s.drone = w.drone;
  s.kind = static_cast<LifecycleKind>(w.kind);
  s.run_id = w.run_id;
  s.nonce = w.nonce;
  s.start_at_ns = w.start_at_ns;
  s.speed = w.speed;
  s.t = w.t;
  s.nonces.assign(w.nonces._buffer, w.nonces._buffer + w.nonces._length);
  s.reason = copy(w.reason);
  if (w.failed_drone && *w.failed_drone)
    s.failure = dex::Failure{copy(w.failed_drone), copy(w.failed_action), w.failed_line, s.reason};
  return s;
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
  w.since = s.since;
  state_to_wire(s.state, w.t, w.x, w.y, w.z, w.battery, w.armed, w.landed, w.pictures);
  return w;
}

StatusSample from_wire(const eamos_wire_Status& w) {
  StatusSample s;
  s.mission_hash = copy(w.mission_hash);
  s.drone = w.drone;
  s.run_id = w.run_id;
  s.nonce = w.nonce;
  s.phase = static_cast<Phase>(w.phase);
  s.busy = w.busy;
  s.end_reached = w.end_reached;
  s.sent = w.sent;
  s.received = w.received;
  s.activations = w.activations;
  s.since = w.since;
  s.state = state_from_wire(w);
  return s;
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
  w.has_reading = e.reading.has_value();
  w.reading = e.reading.value_or(0.0);
  w.reason = borrow(e.reason);
  return w;
}

TraceSample from_wire(const eamos_wire_TraceRecord& w) {
  TraceSample s;
  s.mission_hash = copy(w.mission_hash);
  s.run_id = w.run_id;
  s.drone = w.drone;
  s.seq = w.seq;
  dex::TraceEvent& e = s.event;
  e.t = w.t;
  e.event = copy(w.event);
  e.name = copy(w.name);
  e.line = w.line;
  e.text = copy(w.text);
  e.outcome = copy(w.outcome);
  if (w.value >= 0) e.value = w.value == 1;
  if (w.has_reading) e.reading = w.reading;
  e.reason = copy(w.reason);
  return s;
}

}  // namespace eamos::transport
