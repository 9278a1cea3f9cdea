// failsafe(): the mission failed. Running actions end `cancelled`; an airborne drone lands
// where it is, returns home and lands, or hovers; new actions are refused.
#include <gtest/gtest.h>

#include "helpers.h"
#include "mid/vec.h"

namespace eamos::sim {
namespace {

using mid::Outcome;

class Failsafe : public test::SimTest {};

TEST_F(Failsafe, FailsafeReturnHomeLandsAtHome) {
  config.home = {2, 3, 0};
  airborne(10);
  test::Result fly = run("FlyTo", {30, 30, 12});
  ASSERT_EQ(fly.end.outcome, Outcome::succeeded) << fly.end.reason;
  auto orbit = start("Orbit");
  loop.run_until(loop.now() + 5);
  auto picture = start("TakePicture");
  d().failsafe(fleet::Failsafe::return_home);
  EXPECT_FALSE(orbit->ended);  // reported through the loop
  loop.run_until(loop.now() + 120);
  EXPECT_EQ(orbit->end.outcome, Outcome::cancelled);
  EXPECT_EQ(orbit->end.reason, "failsafe: return_home");
  EXPECT_EQ(picture->end.outcome, Outcome::cancelled);
  mid::DroneState s = d().state();
  EXPECT_DOUBLE_EQ(s.x, 2.0);
  EXPECT_DOUBLE_EQ(s.y, 3.0);
  EXPECT_DOUBLE_EQ(s.z, 0.0);
  EXPECT_TRUE(s.landed);
  EXPECT_FALSE(s.armed);  // a failsafe ends with the motors off
}

TEST_F(Failsafe, FailsafeLandLandsWhereItIs) {
  airborne(10);
  ASSERT_EQ(run("FlyTo", {20, 0, 10}).end.outcome, Outcome::succeeded);
  d().failsafe(fleet::Failsafe::land);
  loop.run_until(loop.now() + 60);
  mid::DroneState s = d().state();
  EXPECT_DOUBLE_EQ(s.x, 20.0);
  EXPECT_DOUBLE_EQ(s.z, 0.0);
  EXPECT_TRUE(s.landed);
}

TEST_F(Failsafe, FailsafeHoverHoldsPosition) {
  airborne(10);
  auto fly = start("FlyByX", {100});
  loop.run_until(loop.now() + 5);
  d().failsafe(fleet::Failsafe::hover);
  loop.run_until(loop.now() + 60);
  EXPECT_EQ(fly->end.outcome, Outcome::cancelled);
  EXPECT_LT(d().state().x, 50.0);
  EXPECT_DOUBLE_EQ(d().state().z, 10.0);
  EXPECT_TRUE(d().velocity() == fleet::Vec3{});
  EXPECT_TRUE(d().state().armed);
}

TEST_F(Failsafe, NewActionsAreRefusedAfterAFailsafe) {
  airborne(10);
  d().failsafe(fleet::Failsafe::hover);
  test::Result r = run("Land");
  EXPECT_EQ(r.end.outcome, Outcome::failed);
  EXPECT_EQ(r.end.reason, "failsafe active (failsafe: hover)");
}

TEST_F(Failsafe, FailsafeOnTheGroundDisarms) {
  ASSERT_EQ(run("Arm").end.outcome, Outcome::succeeded);
  std::vector<bool> armed_seen;
  d().subscribe([&](const mid::DroneState& s) { armed_seen.push_back(s.armed); });
  d().failsafe(fleet::Failsafe::return_home);
  EXPECT_TRUE(armed_seen.empty());  // published through the loop
  loop.run_until(loop.now() + 1);
  EXPECT_FALSE(d().state().armed);
  ASSERT_FALSE(armed_seen.empty());
  EXPECT_FALSE(armed_seen.front());
}

// A DEX that tears down mid-mission must still hear how every action ended, and the loop
// must hold nothing that points into the destroyed drone.
TEST_F(Failsafe, DestroyedDroneEndsItsActionsCancelled) {
  airborne(10);
  auto orbit = start("Orbit");
  auto picture = start("TakePicture");
  loop.run_until(loop.now() + 0.2);
  drone.reset();
  loop.run_until(loop.now() + 60);
  EXPECT_EQ(orbit->end.outcome, Outcome::cancelled);
  EXPECT_EQ(orbit->end.reason, "drone shut down");
  EXPECT_EQ(picture->end.outcome, Outcome::cancelled);
  EXPECT_EQ(loop.size(), 0u);
}

}  // namespace
}  // namespace eamos::sim
