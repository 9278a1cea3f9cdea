// The C++ samples survive the trip through the IDL's C structs field by field.
#include <gtest/gtest.h>

#include "transport/wire_convert.h"

namespace eamos::transport {
namespace {

TEST(Wire, TriggerKeepsEveryField) {
  TriggerSample s;
  s.run_id = 77;
  s.to = 2;
  s.seq = 9;
  s.message = {dex::Message::Kind::cancel, "abc", 1, 42, graph::Branch::false_, 17, 5, 6};
  TriggerSample back = from_wire(to_wire(s));
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
  s.telemetry.state = {1.5, 2, -3, 4.25, 88, true, false, {{"Sensor1", 0.5}, {"Sensor2", 7}}, 3};
  TelemetryOut out;
  to_wire(s, out);
  TelemetrySample back = from_wire(out.c);
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
  EXPECT_EQ(b.sensors, (std::map<std::string, double>{{"Sensor1", 0.5}, {"Sensor2", 7}}));
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
  s.failure = dex::Failure{"Drone1", "Takeoff", 3, s.reason};
  LifecycleSample back = from_wire(to_wire(s));
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
}

TEST(Wire, LifecycleWithoutFailureHasNone) {
  LifecycleSample s;
  s.kind = LifecycleKind::finished;
  EXPECT_FALSE(from_wire(to_wire(s)).failure);
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
  s.state.z = 12;
  s.state.landed = false;
  StatusSample back = from_wire(to_wire(s));
  EXPECT_EQ(back.phase, Phase::failed);
  EXPECT_TRUE(back.busy);
  EXPECT_TRUE(back.end_reached);
  EXPECT_EQ(back.sent, 100u);
  EXPECT_EQ(back.received, 99u);
  EXPECT_EQ(back.activations, 1000u);
  EXPECT_EQ(back.since, 4.5);
  EXPECT_EQ(back.state.z, 12);
  EXPECT_FALSE(back.state.landed);
}

TEST(Wire, TraceKeepsOptionalValueAndReading) {
  TraceSample s;
  s.drone = 1;
  s.seq = 4;
  s.event = {2.5, "", "condition", "If", 12, "Drone1.X() > 3", "", false, std::nullopt, ""};
  TraceSample back = from_wire(to_wire(s));
  ASSERT_TRUE(back.event.value);
  EXPECT_FALSE(*back.event.value);
  EXPECT_FALSE(back.event.reading);
  EXPECT_EQ(back.event.text, "Drone1.X() > 3");
  EXPECT_EQ(back.event.line, 12);
  s.event = {3, "", "sensor", "Sensor1", 13, "", "", std::nullopt, 41.5, ""};
  back = from_wire(to_wire(s));
  EXPECT_FALSE(back.event.value);
  ASSERT_TRUE(back.event.reading);
  EXPECT_EQ(*back.event.reading, 41.5);
}

}  // namespace
}  // namespace eamos::transport
