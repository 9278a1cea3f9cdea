// hold_motion / resume_motion (the Uniform Space's give-way, dex/separation.h): a held motion
// stops where the drone can stop and keeps running, its deadline standing still, and flies on
// to its own goal when resumed.
#include <gtest/gtest.h>

#include <cmath>

#include "helpers.h"

namespace eamos::sim {
namespace {

using mid::Outcome;

class GiveWay : public test::SimTest {};

TEST_F(GiveWay, AHeldFlyToStopsKeepsRunningPastItsDeadlineAndFliesOnToItsGoal) {
  config.timeouts_s["FlyTo"] = 10;
  airborne(5);
  auto fly = start("FlyTo", {40, 0, 5});
  loop.run_until(loop.now() + 2);
  ASSERT_TRUE(d().hold_motion(0.0));
  EXPECT_TRUE(d().motion_held());
  EXPECT_FALSE(d().hold_motion(0.0));  // already held
  loop.run_until(loop.now() + 20);     // twice its deadline, held
  EXPECT_FALSE(fly->ended);
  const mid::DroneState held = d().state();
  EXPECT_LT(held.x, 40.0);
  EXPECT_LT(std::hypot(d().velocity().x, d().velocity().y), 1e-9);  // stopped, not drifting
  ASSERT_TRUE(d().resume_motion());
  EXPECT_FALSE(d().motion_held());
  run_until_ended(*fly);
  EXPECT_EQ(fly->end.outcome, Outcome::succeeded) << fly->end.reason;
  EXPECT_DOUBLE_EQ(d().state().x, 40.0);
}

TEST_F(GiveWay, AHoldClimbsByWhatItIsAskedAndHoverAndOrbitAreNeverHeld) {
  airborne(5);
  auto fly = start("FlyTo", {40, 0, 5});
  loop.run_until(loop.now() + 2);
  ASSERT_TRUE(d().hold_motion(1.5));
  loop.run_until(loop.now() + 10);
  EXPECT_NEAR(d().state().z, 6.5, 1e-9);
  ASSERT_TRUE(d().resume_motion());
  run_until_ended(*fly);
  EXPECT_EQ(fly->end.outcome, Outcome::succeeded);
  auto hover = start("Hover");
  loop.run_until(loop.now() + 1);
  EXPECT_FALSE(d().hold_motion(0.0));
  auto orbit = start("Orbit");
  loop.run_until(loop.now() + 1);
  EXPECT_FALSE(d().hold_motion(0.0));
  EXPECT_FALSE(d().resume_motion());
}

TEST_F(GiveWay, AFailsafeEndsAHeldMotionAndNothingResumes) {
  airborne(5);
  auto fly = start("FlyTo", {40, 0, 5});
  loop.run_until(loop.now() + 2);
  ASSERT_TRUE(d().hold_motion(0.0));
  d().failsafe(fleet::Failsafe::land);
  loop.run_until(loop.now() + 30);
  EXPECT_EQ(fly->end.outcome, Outcome::cancelled);
  EXPECT_FALSE(d().resume_motion());
  EXPECT_TRUE(d().state().landed);
}


// Separation predicts a drone along the line to its goal: the goal is there from the start
// of the motion, held or not, and gone with it; Hover has none.
TEST_F(GiveWay, TheGoalOfTheRunningMotionIsKnownHeldOrNotAndGoneWithIt) {
  auto goal_is = [this](double x, double y, double z) {
    const std::optional<fleet::Vec3> g = d().motion_goal();
    return g && g->x == x && g->y == y && g->z == z;
  };
  airborne(5);
  EXPECT_FALSE(d().motion_goal().has_value());
  auto fly = start("FlyTo", {40, 10, 5});
  ASSERT_TRUE(d().motion_goal().has_value());
  EXPECT_TRUE(goal_is(40, 10, 5));
  loop.run_until(loop.now() + 2);
  ASSERT_TRUE(d().hold_motion(0.0));
  ASSERT_TRUE(d().motion_goal().has_value());
  EXPECT_TRUE(goal_is(40, 10, 5));
  ASSERT_TRUE(d().resume_motion());
  run_until_ended(*fly);
  EXPECT_FALSE(d().motion_goal().has_value());
  auto hover = start("Hover");
  loop.run_until(loop.now() + 1);
  EXPECT_FALSE(d().motion_goal().has_value());
  auto land = start("Land");
  ASSERT_TRUE(d().motion_goal().has_value());
  EXPECT_DOUBLE_EQ(d().motion_goal()->z, 0.0);
}

}  // namespace
}  // namespace eamos::sim
