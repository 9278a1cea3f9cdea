// The simulated autopilot refuses what a real one refuses: the action ends `failed` with the
// reason in words, through the loop, and the vehicle does not change.
#include <gtest/gtest.h>

#include "helpers.h"

namespace eamos::sim {
namespace {

using mid::Outcome;

class Refusals : public test::SimTest {};

TEST_F(Refusals, TakeoffWhileDisarmedFails) {
  test::Result r = run("Takeoff", {5});
  EXPECT_EQ(r.end.outcome, Outcome::failed);
  EXPECT_EQ(r.end.reason, "disarmed: arm before Takeoff");
  EXPECT_EQ(r.end.failure, mid::FailureReason::refused);
  EXPECT_TRUE(d().state().landed);
  EXPECT_DOUBLE_EQ(d().state().z, 0.0);
}

TEST_F(Refusals, AnyMotionWhileDisarmedFails) {
  for (auto [name, args] : std::vector<std::pair<std::string, std::vector<double>>>{
           {"Land", {}}, {"FlyTo", {1, 1, 1}}, {"FlyBy", {1, 1, 1}}, {"FlyByX", {1}},
           {"FlyByY", {1}}, {"FlyByZ", {1}}, {"Hover", {}}, {"Hover", {2}}, {"Orbit", {}},
           {"ReturnHome", {}}}) {
    test::Result r = run(name, args);
    EXPECT_EQ(r.end.outcome, Outcome::failed) << name;
    EXPECT_EQ(r.end.reason, "disarmed: arm before " + name);
  }
}

TEST_F(Refusals, DisarmInAirFails) {
  airborne(10);
  test::Result r = run("Disarm");
  EXPECT_EQ(r.end.outcome, Outcome::failed);
  EXPECT_EQ(r.end.reason, "in the air at z = 10.0 m: land before disarming");
  EXPECT_TRUE(d().state().armed);
}

TEST_F(Refusals, ArmWithEmptyBatteryFails) {
  config.battery_percent = 0;
  test::Result r = run("Arm");
  EXPECT_EQ(r.end.outcome, Outcome::failed);
  EXPECT_EQ(r.end.reason, "battery empty: cannot arm");
  EXPECT_FALSE(d().state().armed);
}

TEST_F(Refusals, FlyingFromTheGroundNeedsATakeoffFirst) {
  ASSERT_EQ(run("Arm").end.outcome, Outcome::succeeded);
  test::Result r = run("FlyByX", {5});
  EXPECT_EQ(r.end.outcome, Outcome::failed);
  EXPECT_EQ(r.end.reason, "on the ground: take off before FlyByX");
}

TEST_F(Refusals, TargetAtOrBelowTheGroundFails) {
  airborne(5);
  test::Result r = run("FlyByZ", {-6});
  EXPECT_EQ(r.end.outcome, Outcome::failed);
  EXPECT_EQ(r.end.reason, "target z = -1.0 m is not above the ground (z = 0.0 m); use Land to land");
}

TEST_F(Refusals, TargetsAboveMaxAltitudeFail) {
  config.limits.max_altitude_m = 50;
  ASSERT_EQ(run("Arm").end.outcome, Outcome::succeeded);
  EXPECT_EQ(run("Takeoff", {60}).end.outcome, Outcome::failed);
  ASSERT_EQ(run("Takeoff", {40}).end.outcome, Outcome::succeeded);
  test::Result r = run("FlyTo", {0, 0, 51});
  EXPECT_EQ(r.end.outcome, Outcome::failed);
  EXPECT_EQ(r.end.reason, "target z = 51.0 m is above max_altitude 50.0 m over the ground");
}

TEST_F(Refusals, ActionTheTypeLacksFails) {
  type = fleet::generic_multirotor("Quad");
  fleet::set_sensors(type, 2);
  test::Result r = run("Sensor3");
  EXPECT_EQ(r.end.outcome, Outcome::failed);
  EXPECT_EQ(r.end.reason, "type 'Quad' has no action 'Sensor3'");
}

TEST_F(Refusals, BadArgumentsFail) {
  airborne(5);
  EXPECT_EQ(run("Orbit", {-2}).end.reason, "orbit radius must be positive, got -2.0 m");
  EXPECT_EQ(run("Hover", {-1}).end.reason, "hover duration must not be negative");
  EXPECT_EQ(run("FlyTo", {1}).end.reason, "FlyTo takes (x_m, y_m, z_m), not 1 argument");
}

TEST_F(Refusals, RefusalIsReportedThroughTheLoopNotInsideStart) {
  auto r = start("Takeoff", {5});
  EXPECT_NE(r->id, mid::kNoAction);
  EXPECT_FALSE(r->ended);
  loop.run_until_idle();
  EXPECT_TRUE(r->ended);
  EXPECT_EQ(r->end.outcome, Outcome::failed);
}

TEST_F(Refusals, RefusedMotionLeavesTheRunningOneAlone) {
  airborne(5);
  auto orbit = start("Orbit");
  loop.run_until(loop.now() + 5);
  EXPECT_EQ(run("FlyByZ", {-10}).end.outcome, Outcome::failed);
  loop.run_until(loop.now() + 1);
  EXPECT_FALSE(orbit->ended);
}

TEST_F(Refusals, DisarmWhileAMotionRunsFails) {
  ASSERT_EQ(run("Arm").end.outcome, Outcome::succeeded);
  auto takeoff = start("Takeoff", {5});
  test::Result r = run("Disarm");
  EXPECT_EQ(r.end.outcome, Outcome::failed);
  EXPECT_EQ(r.end.reason, "Takeoff is running: cannot disarm");
}

}  // namespace
}  // namespace eamos::sim
