// The C++ samples survive the trip through the IDL's C structs field by field, and a
// received sample that breaks a rule (drone index outside the fleet, unknown enum, NaN or
// infinity, a string too long or not UTF-8) is refused with the reason, never converted.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "transport/wire_convert.h"

namespace eamos::transport {
namespace {

/// The missions of these tests have five drones.
const WireLimits kFiveDrones{5};

/// The sample `w` converts back to; a test failure when it is refused.
template <typename Sample, typename Wire>
Sample back_from(const Wire& w) {
  Sample s;
  std::string why;
  EXPECT_TRUE(from_wire(w, kFiveDrones, s, why)) << why;
  return s;
}

/// Why `w` is refused; "" (and a test failure) when it is accepted.
template <typename Sample, typename Wire>
std::string refusal(const Wire& w) {
  Sample s;
  std::string why;
  EXPECT_FALSE(from_wire(w, kFiveDrones, s, why));
  return why;
}

TEST(Wire, TriggerKeepsEveryField) {
  TriggerSample s;
  s.run_id = 77;
  s.to = 2;
  s.seq = 9;
  s.message = {dex::Message::Kind::cancel, "abc", 1, 42, graph::Branch::false_, 17, 5, 6};
  TriggerSample back = back_from<TriggerSample>(to_wire(s));
  EXPECT_EQ(back.run_id, 77u);
  EXPECT_EQ(back.to, 2);
  EXPECT_EQ(back.seq, 9u);
  EXPECT_EQ(back.message.kind, dex::Message::Kind::cancel);
  EXPECT_EQ(back.message.mission_hash, "abc");
  EXPECT_EQ(back.message.from, 1);
  EXPECT_EQ(back.message.meg, 42);
  EXPECT_EQ(back.message.branch, graph::Branch::false_);
  EXPECT_EQ(back.message.scope, 17);
  EXPECT_EQ(back.message.epoch, 5);
  EXPECT_EQ(back.message.body_epoch, 6);
}

TEST(Wire, TelemetryKeepsStateAndSensors) {
  TelemetrySample s;
  s.run_id = 3;
  s.telemetry.mission_hash = "h";
  s.telemetry.from = 4;
  s.telemetry.state = {1.5, 2, -3, 4.25, 88, true, false, {}, 3};
  s.telemetry.state.sensors["Sensor1"] = 0.5;
  s.telemetry.state.sensors["Sensor2"] = 7;
  TelemetryOut out;
  to_wire(s, out);
  TelemetrySample back = back_from<TelemetrySample>(out.c);
  EXPECT_EQ(back.run_id, 3u);
  EXPECT_EQ(back.telemetry.from, 4);
  EXPECT_EQ(back.telemetry.mission_hash, "h");
  const mid::DroneState& b = back.telemetry.state;
  EXPECT_EQ(b.t, 1.5);
  EXPECT_EQ(b.x, 2);
  EXPECT_EQ(b.y, -3);
  EXPECT_EQ(b.z, 4.25);
  EXPECT_EQ(b.battery, 88);
  EXPECT_TRUE(b.armed);
  EXPECT_FALSE(b.landed);
  EXPECT_EQ(b.pictures, 3);
  ASSERT_EQ(b.sensors.size(), 2u);
  EXPECT_EQ(b.sensors.at("Sensor1"), 0.5);
  EXPECT_EQ(b.sensors.at("Sensor2"), 7);
}

TEST(Wire, LifecycleKeepsStartAndFailure) {
  LifecycleSample s;
  s.mission_hash = "h";
  s.drone = kGround;
  s.kind = LifecycleKind::abort;
  s.run_id = 5;
  s.nonce = 6;
  s.start_at_ns = 1234567890123;
  s.speed = 2.5;
  s.t = 9.75;
  s.nonces = {11, 12, 13};
  s.reason = "Drone1.Takeoff (line 3) failed: disarmed";
  s.failure = dex::Failure{"Drone1", "Takeoff", 3, s.reason, mid::FailureReason::refused, "MAV_RESULT_DENIED"};
  LifecycleSample back = back_from<LifecycleSample>(to_wire(s));
  EXPECT_EQ(back.drone, kGround);
  EXPECT_EQ(back.kind, LifecycleKind::abort);
  EXPECT_EQ(back.run_id, 5u);
  EXPECT_EQ(back.nonce, 6u);
  EXPECT_EQ(back.start_at_ns, 1234567890123);
  EXPECT_EQ(back.speed, 2.5);
  EXPECT_EQ(back.t, 9.75);
  EXPECT_EQ(back.nonces, (std::vector<std::uint64_t>{11, 12, 13}));
  EXPECT_EQ(back.reason, s.reason);
  ASSERT_TRUE(back.failure);
  EXPECT_EQ(back.failure->drone, "Drone1");
  EXPECT_EQ(back.failure->action, "Takeoff");
  EXPECT_EQ(back.failure->line, 3);
  EXPECT_EQ(back.failure->kind, mid::FailureReason::refused);
  EXPECT_EQ(back.failure->detail, "MAV_RESULT_DENIED");
}

TEST(Wire, AnAbortWithAnUnknownFailureKindIsRefused) {
  LifecycleSample s;
  s.kind = LifecycleKind::abort;
  s.failure = dex::Failure{"Drone1", "Takeoff", 3, "r", mid::FailureReason::refused, ""};
  eamos_wire_Lifecycle w = to_wire(s);
  w.failed_kind = 99;
  EXPECT_NE(refusal<LifecycleSample>(w).find("failed_kind 99 is not a known value"), std::string::npos);
}

TEST(Wire, ReadyCarriesWhereTheVehicleStandsAndItsDeclaredHome) {
  LifecycleSample s;
  s.kind = LifecycleKind::ready;
  s.fix = mid::GlobalFix{47.397742, 8.545594};
  s.home_x = 0;
  s.home_y = 5;
  s.home_tolerance = 4;
  LifecycleSample back = back_from<LifecycleSample>(to_wire(s));
  ASSERT_TRUE(back.fix);
  EXPECT_EQ(back.fix->lat_deg, 47.397742);
  EXPECT_EQ(back.fix->lon_deg, 8.545594);
  EXPECT_EQ(back.home_y, 5);
  EXPECT_EQ(back.home_tolerance, 4);
  EXPECT_FALSE(back_from<LifecycleSample>(to_wire(LifecycleSample{})).fix);
}

TEST(Wire, AReadyWithALatitudeBeyondThePolesIsRefused) {
  LifecycleSample s;
  s.fix = mid::GlobalFix{91.0, 0.0};
  EXPECT_NE(refusal<LifecycleSample>(to_wire(s)).find("fix_lat"), std::string::npos);
}

TEST(Wire, LifecycleWithoutFailureHasNone) {
  LifecycleSample s;
  s.kind = LifecycleKind::finished;
  EXPECT_FALSE(back_from<LifecycleSample>(to_wire(s)).failure);
}

TEST(Wire, StatusKeepsCountersAndState) {
  StatusSample s;
  s.mission_hash = "h";
  s.drone = 2;
  s.run_id = 8;
  s.phase = Phase::failed;
  s.busy = true;
  s.end_reached = true;
  s.sent = 100;
  s.received = 99;
  s.activations = 1000;
  s.since = 4.5;
  s.heard = 3;
  s.state.z = 12;
  s.state.landed = false;
  StatusSample back = back_from<StatusSample>(to_wire(s));
  EXPECT_EQ(back.phase, Phase::failed);
  EXPECT_TRUE(back.busy);
  EXPECT_TRUE(back.end_reached);
  EXPECT_EQ(back.sent, 100u);
  EXPECT_EQ(back.received, 99u);
  EXPECT_EQ(back.activations, 1000u);
  EXPECT_EQ(back.since, 4.5);
  EXPECT_EQ(back.heard, 3);
  EXPECT_EQ(back.state.z, 12);
  EXPECT_FALSE(back.state.landed);
}

TEST(Wire, TraceKeepsOptionalValueAndReading) {
  TraceSample s;
  s.drone = 1;
  s.seq = 4;
  s.event = {2.5, "", "condition", "If", 12, "Drone1.X() > 3", "", false, std::nullopt, ""};
  TraceSample back = back_from<TraceSample>(to_wire(s));
  ASSERT_TRUE(back.event.value);
  EXPECT_FALSE(*back.event.value);
  EXPECT_FALSE(back.event.reading);
  EXPECT_EQ(back.event.text, "Drone1.X() > 3");
  EXPECT_EQ(back.event.line, 12);
  s.event = {3, "", "sensor", "Sensor1", 13, "", "", std::nullopt, 41.5, ""};
  back = back_from<TraceSample>(to_wire(s));
  EXPECT_FALSE(back.event.value);
  ASSERT_TRUE(back.event.reading);
  EXPECT_EQ(*back.event.reading, 41.5);
}

// The ground's log line and trace of a failed action in a DEX process name its kind and the
// vehicle's words, as an in-process run's do.
TEST(Wire, TraceKeepsAFailedActionsKindAndDetail) {
  TraceSample s;
  s.drone = 0;
  s.event.t = 1.5;
  s.event.event = "end";
  s.event.name = "Takeoff";
  s.event.outcome = "failed";
  s.event.failure = "refused";
  s.event.detail = "MAV_RESULT_DENIED";
  TraceSample back = back_from<TraceSample>(to_wire(s));
  EXPECT_EQ(back.event.failure, "refused");
  EXPECT_EQ(back.event.detail, "MAV_RESULT_DENIED");
}

TEST(WireRules, RefusesATriggerFromOrToADroneOutsideTheFleet) {
  TriggerSample s;
  s.to = 1;
  s.message = {dex::Message::Kind::ended, "h", 99, 3, graph::Branch::any, -1, 0, 0};
  EXPECT_EQ(refusal<TriggerSample>(to_wire(s)), "from 99 is not a drone of the mission (5 drones)");
  s.message.from = -1;
  EXPECT_EQ(refusal<TriggerSample>(to_wire(s)), "from -1 is not a drone of the mission (5 drones)");
  s.message.from = 0;
  s.to = 5;
  EXPECT_EQ(refusal<TriggerSample>(to_wire(s)), "to 5 is not a drone of the mission (5 drones)");
}

TEST(WireRules, RefusesUnknownEnumValues) {
  TriggerSample s;
  s.message = {dex::Message::Kind::ended, "h", 0, 3, graph::Branch::any, -1, 0, 0};
  eamos_wire_Trigger w = to_wire(s);
  w.branch = 77;
  EXPECT_EQ(refusal<TriggerSample>(w), "branch 77 is not a known value");
  w = to_wire(s);
  uint32_t nine = 9;
  std::memcpy(&w.kind, &nine, sizeof nine);  // as a hostile writer's CDR would carry it
  EXPECT_EQ(refusal<TriggerSample>(w), "kind 9 is not a known value");

  LifecycleSample l;
  eamos_wire_Lifecycle lw = to_wire(l);
  uint32_t minus_three = static_cast<uint32_t>(-3);
  std::memcpy(&lw.kind, &minus_three, sizeof minus_three);
  EXPECT_EQ(refusal<LifecycleSample>(lw), "kind 4294967293 is not a known value");
  StatusSample st;
  eamos_wire_Status sw = to_wire(st);
  uint32_t five = 5;
  std::memcpy(&sw.phase, &five, sizeof five);
  EXPECT_EQ(refusal<StatusSample>(sw), "phase 5 is not a known value");
}

TEST(WireRules, RefusesTelemetryWithNaNOrInfinity) {
  TelemetrySample s;
  s.telemetry.mission_hash = "h";
  s.telemetry.from = 1;
  s.telemetry.state.x = std::nan("");
  TelemetryOut out;
  to_wire(s, out);
  EXPECT_EQ(refusal<TelemetrySample>(out.c), "x is NaN");
  s.telemetry.state.x = 0;
  s.telemetry.state.z = std::numeric_limits<double>::infinity();
  to_wire(s, out);
  EXPECT_EQ(refusal<TelemetrySample>(out.c), "z is infinite");
  s.telemetry.state.z = 0;
  s.telemetry.state.sensors["Sensor1"] = std::nan("");
  to_wire(s, out);
  EXPECT_EQ(refusal<TelemetrySample>(out.c), "sensor value is NaN");
}

TEST(WireRules, RefusesStringsTooLongOrNotUtf8) {
  TraceSample s;
  s.drone = 1;
  s.event.event = "action";
  s.event.text = std::string(kMaxWireText + 1, 'x');
  EXPECT_EQ(refusal<TraceSample>(to_wire(s)), "text is longer than 4096 bytes");
  s.event.text = "Drone1.FlyTo(\xC3\x28)";  // a lead byte without its continuation
  EXPECT_EQ(refusal<TraceSample>(to_wire(s)), "text is not UTF-8");
  s.event.text = "\xED\xA0\x80";  // a UTF-16 surrogate written as UTF-8
  EXPECT_EQ(refusal<TraceSample>(to_wire(s)), "text is not UTF-8");
  s.event.text = "Höhe 3 m";
  EXPECT_EQ(back_from<TraceSample>(to_wire(s)).event.text, "Höhe 3 m");
  TriggerSample t;
  t.message.mission_hash = std::string(65, 'a');
  EXPECT_EQ(refusal<TriggerSample>(to_wire(t)), "mission_hash is longer than 64 bytes");
}

TEST(WireRules, RefusesTooManySensorsAndNegativeCounts) {
  TelemetrySample s;
  s.telemetry.from = 0;
  for (int i = 1; i <= 65; ++i) s.telemetry.state.sensors["Sensor" + std::to_string(i)] = i;
  TelemetryOut out;
  to_wire(s, out);
  EXPECT_EQ(refusal<TelemetrySample>(out.c), "sensors holds 65 entries, more than 64");
  StatusSample st;
  st.state.pictures = -1;
  EXPECT_EQ(refusal<StatusSample>(to_wire(st)), "pictures -1 is below 0");
  st.state.pictures = 0;
  st.heard = -1;  // the ground's waves count on it
  EXPECT_EQ(refusal<StatusSample>(to_wire(st)).rfind("heard -1 is outside 0 to ", 0), 0u);
  TraceSample tr;
  eamos_wire_TraceRecord tw = to_wire(tr);
  tw.value = 2;
  EXPECT_EQ(refusal<TraceSample>(tw), "value 2 is outside -1 to 1");
}

TEST(WireRules, AcceptsTheGroundAsALifecycleSenderButNotAsAStatusSender) {
  LifecycleSample l;
  l.drone = kGround;
  back_from<LifecycleSample>(to_wire(l));
  l.speed = 0;
  EXPECT_EQ(refusal<LifecycleSample>(to_wire(l)), "speed is not positive");
  StatusSample st;
  st.drone = kGround;
  EXPECT_EQ(refusal<StatusSample>(to_wire(st)), "drone -1 is not a drone of the mission (5 drones)");
}

}  // namespace
}  // namespace eamos::transport
