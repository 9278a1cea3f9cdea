// libFuzzer target of from_wire: every field of every DDS sample type filled from the
// fuzzer's bytes (any integer, any double including NaN and infinities, strings of any
// bytes and length, sequences of any length) must be converted or refused with a reason,
// never crash. A sample that is accepted must obey the rules the DEX relies on.
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <deque>
#include <string>
#include <vector>

#include "transport/wire_convert.h"

namespace {

using namespace eamos::transport;

/// Strings and sequences the structs point into, alive for one input (a deque: the
/// strings never move while more are added).
struct Storage {
  std::deque<std::string> strings;
  std::vector<eamos_wire_SensorValue> sensors;
  std::vector<uint64_t> nonces;
};

char* text(FuzzedDataProvider& in, Storage& keep) {
  keep.strings.push_back(in.ConsumeRandomLengthString(5000));
  return keep.strings.back().data();
}

double number(FuzzedDataProvider& in) {
  switch (in.ConsumeIntegralInRange(0, 3)) {
    case 0: return std::nan("");
    case 1: return in.ConsumeBool() ? INFINITY : -INFINITY;
    default: return in.ConsumeFloatingPoint<double>();
  }
}

/// Any 32 bits into an IDL enum field, as a hostile writer's CDR could carry them.
template <typename Enum>
void set_raw(Enum& field, uint32_t v) {
  std::memcpy(&field, &v, sizeof v);
}

void check(bool accepted, int drone, int drones) {
  if (accepted && (drone < -1 || drone >= drones)) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  Storage keep;
  WireLimits limits{in.ConsumeIntegralInRange(0, 8)};
  int drones = limits.drones > 0 ? limits.drones : kMaxWireDrones;
  std::string why;

  eamos_wire_Trigger t{};
  t.mission_hash = text(in, keep);
  t.from = in.ConsumeIntegral<int32_t>();
  t.to = in.ConsumeIntegral<int32_t>();
  set_raw(t.kind, in.ConsumeIntegral<uint32_t>());
  t.meg = in.ConsumeIntegral<int32_t>();
  t.branch = in.ConsumeIntegral<int32_t>();
  t.scope = in.ConsumeIntegral<int32_t>();
  t.epoch = in.ConsumeIntegral<int64_t>();
  t.body_epoch = in.ConsumeIntegral<int64_t>();
  TriggerSample ts;
  bool ok = from_wire(t, limits, ts, why);
  check(ok, ts.message.from, drones);
  check(ok, ts.to, drones);

  eamos_wire_Telemetry m{};
  m.mission_hash = text(in, keep);
  m.from = in.ConsumeIntegral<int32_t>();
  m.t = number(in), m.x = number(in), m.y = number(in), m.z = number(in), m.battery = number(in);
  m.pictures = in.ConsumeIntegral<int32_t>();
  std::size_t sensors = in.ConsumeIntegralInRange<std::size_t>(0, 80);
  keep.sensors.reserve(sensors);  // filled before the struct points into it
  for (std::size_t i = 0; i < sensors; ++i) {
    char* name = text(in, keep);
    keep.sensors.push_back({name, number(in)});
  }
  m.sensors._length = m.sensors._maximum = static_cast<uint32_t>(keep.sensors.size());
  m.sensors._buffer = keep.sensors.data();
  TelemetrySample ms;
  ok = from_wire(m, limits, ms, why);
  check(ok, ms.telemetry.from, drones);
  if (ok && (!std::isfinite(ms.telemetry.state.x) || ms.telemetry.from < 0)) __builtin_trap();

  eamos_wire_Lifecycle l{};
  l.mission_hash = text(in, keep);
  l.drone = in.ConsumeIntegral<int32_t>();
  set_raw(l.kind, in.ConsumeIntegral<uint32_t>());
  l.speed = number(in), l.t = number(in);
  std::size_t nonces = in.ConsumeIntegralInRange<std::size_t>(0, 20);
  for (std::size_t i = 0; i < nonces; ++i) keep.nonces.push_back(in.ConsumeIntegral<uint64_t>());
  l.nonces._length = l.nonces._maximum = static_cast<uint32_t>(keep.nonces.size());
  l.nonces._buffer = keep.nonces.data();
  l.reason = text(in, keep);
  l.failed_drone = text(in, keep);
  l.failed_action = text(in, keep);
  l.failed_line = in.ConsumeIntegral<int32_t>();
  LifecycleSample ls;
  check(from_wire(l, limits, ls, why), ls.drone, drones);

  eamos_wire_Status s{};
  s.mission_hash = text(in, keep);
  s.drone = in.ConsumeIntegral<int32_t>();
  set_raw(s.phase, in.ConsumeIntegral<uint32_t>());
  s.since = number(in), s.t = number(in), s.x = number(in), s.y = number(in), s.z = number(in);
  s.battery = number(in);
  s.pictures = in.ConsumeIntegral<int32_t>();
  StatusSample ss;
  ok = from_wire(s, limits, ss, why);
  check(ok, ss.drone, drones);
  if (ok && ss.drone < 0) __builtin_trap();

  eamos_wire_TraceRecord r{};
  r.mission_hash = text(in, keep);
  r.drone = in.ConsumeIntegral<int32_t>();
  r.t = number(in);
  r.event = text(in, keep);
  r.name = text(in, keep);
  r.line = in.ConsumeIntegral<int32_t>();
  r.text = text(in, keep);
  r.outcome = text(in, keep);
  r.value = in.ConsumeIntegral<int16_t>();
  r.has_reading = in.ConsumeBool();
  r.reading = number(in);
  r.reason = text(in, keep);
  r.failure = text(in, keep);
  r.detail = text(in, keep);
  TraceSample rs;
  check(from_wire(r, limits, rs, why), rs.drone, drones);
  return 0;
}
