// Motion actions of the simulated multirotor: takeoff and landing phases, flights within the
// limits, orbit, hover, return home; one motion at a time, a new one preempts the old.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "helpers.h"
#include "mid/vec.h"
#include "sim/motion.h"

namespace eamos::sim {
namespace {

using mid::Outcome;

class Motion : public test::SimTest {};

TEST_F(Motion, ArmSetsArmedWithoutMoving) {
  test::Result r = run("Arm");
  EXPECT_EQ(r.end.outcome, Outcome::succeeded);
  EXPECT_EQ(r.end.reason, "");
  mid::DroneState s = d().state();
  EXPECT_TRUE(s.armed);
  EXPECT_TRUE(s.landed);
  EXPECT_DOUBLE_EQ(s.y, 0.0);
}

TEST_F(Motion, TakeoffClimbsToAltitudeWithinClimbLimit) {
  config.limits.max_climb_mps = 2;
  config.home = {3, 4, 0};
  ASSERT_EQ(run("Arm").end.outcome, Outcome::succeeded);
  double t0 = loop.now();
  test::Result r = run("Takeoff", {12});
  EXPECT_EQ(r.end.outcome, Outcome::succeeded);
  EXPECT_GE(r.t - t0, 12.0 / 2.0);
  mid::DroneState s = d().state();
  EXPECT_DOUBLE_EQ(s.z, 12.0);
  EXPECT_DOUBLE_EQ(s.x, 3.0);
  EXPECT_DOUBLE_EQ(s.y, 4.0);
  EXPECT_FALSE(s.landed);
}

TEST_F(Motion, FlyToReachesTargetWithinSpeedLimit) {
  config.limits.max_speed_mps = 4;
  airborne(10);
  double t0 = loop.now();
  double fastest = 0;
  d().subscribe([&](const mid::DroneState&) {
    fastest = std::max(fastest, horizontal_norm(d().velocity()));
  });
  test::Result r = run("FlyTo", {30, 40, 10});
  EXPECT_EQ(r.end.outcome, Outcome::succeeded);
  EXPECT_GE(r.t - t0, 50.0 / 4.0);  // 50 m at no more than 4 m/s
  EXPECT_LE(fastest, 4.0 + 1e-9);
  EXPECT_GT(fastest, 3.9);  // and it does get up to speed
  mid::DroneState s = d().state();
  EXPECT_DOUBLE_EQ(s.x, 30.0);
  EXPECT_DOUBLE_EQ(s.y, 40.0);
}

// Listing 2 waits for `Drone1.X() >= 5` after `FlyByX(5)`: the flight must end exactly there.
TEST_F(Motion, FlyByEndsExactlyAtTheOffset) {
  airborne(3);
  ASSERT_EQ(run("FlyByX", {5}).end.outcome, Outcome::succeeded);
  EXPECT_GE(d().state().x, 5.0);
  ASSERT_EQ(run("FlyBy", {-1, 2, 0.5}).end.outcome, Outcome::succeeded);
  ASSERT_EQ(run("FlyByY", {-2}).end.outcome, Outcome::succeeded);
  ASSERT_EQ(run("FlyByZ", {1.5}).end.outcome, Outcome::succeeded);
  mid::DroneState s = d().state();
  EXPECT_DOUBLE_EQ(s.x, 4.0);
  EXPECT_DOUBLE_EQ(s.y, 0.0);
  EXPECT_DOUBLE_EQ(s.z, 5.0);
}

TEST_F(Motion, LandSetsLandedAndDisarmAllowedAfter) {
  config.limits.max_descent_mps = 1;
  airborne(6);
  double t0 = loop.now();
  test::Result land = run("Land");
  EXPECT_EQ(land.end.outcome, Outcome::succeeded);
  EXPECT_GE(land.t - t0, 6.0 / 1.0);
  mid::DroneState s = d().state();
  EXPECT_TRUE(s.landed);
  EXPECT_TRUE(s.armed);  // landing does not disarm: the mission does
  EXPECT_DOUBLE_EQ(s.z, 0.0);
  EXPECT_EQ(run("Disarm").end.outcome, Outcome::succeeded);
  EXPECT_FALSE(d().state().armed);
}

TEST_F(Motion, LandOnTheGroundSucceedsAtOnce) {
  ASSERT_EQ(run("Arm").end.outcome, Outcome::succeeded);
  double t0 = loop.now();
  test::Result r = run("Land");
  EXPECT_EQ(r.end.outcome, Outcome::succeeded);
  EXPECT_DOUBLE_EQ(r.t, t0);
}

// Listing 2: Drone2's endless Orbit() ends when its Land() starts.
TEST_F(Motion, NewMotionPreemptsRunningOrbit) {
  airborne(10);
  auto orbit = start("Orbit");
  loop.run_until(loop.now() + 20);
  ASSERT_FALSE(orbit->ended);
  test::Result land = run("Land");
  ASSERT_TRUE(orbit->ended);
  EXPECT_EQ(orbit->end.outcome, Outcome::preempted);
  EXPECT_EQ(orbit->end.reason, "preempted by Land");
  EXPECT_LE(orbit->t, land.t);
  EXPECT_EQ(land.end.outcome, Outcome::succeeded);
  EXPECT_TRUE(d().state().landed);
}

TEST_F(Motion, OrbitCirclesWhereItStartedAtDefaultRadius) {
  config.home = {10, 20, 0};
  airborne(8);
  auto orbit = start("Orbit");
  loop.run_until(loop.now() + 15);  // out to the circle and up to speed
  double min_r = 1e9, max_r = 0;
  double angle_travelled = 0, last = std::atan2(d().state().y - 20, d().state().x - 10);
  for (int i = 0; i < 400; ++i) {
    loop.run_until(loop.now() + 0.1);
    mid::DroneState s = d().state();
    double r = std::hypot(s.x - 10, s.y - 20);
    min_r = std::min(min_r, r);
    max_r = std::max(max_r, r);
    double a = std::atan2(s.y - 20, s.x - 10);
    angle_travelled += std::remainder(a - last, 2 * std::numbers::pi);
    last = a;
    EXPECT_DOUBLE_EQ(s.z, 8.0);
  }
  EXPECT_NEAR(min_r, 5.0, 1e-9);
  EXPECT_NEAR(max_r, 5.0, 1e-9);
  EXPECT_GT(angle_travelled, 2 * std::numbers::pi);  // more than once round, counter-clockwise
  EXPECT_FALSE(orbit->ended);             // Orbit() has no end of its own
}

TEST_F(Motion, OrbitKeepsItsSpeedWithinTheLimits) {
  config.limits.max_speed_mps = 3;
  airborne(8);
  start("Orbit", {20});
  loop.run_until(loop.now() + 60);
  double speed = norm(d().velocity());
  EXPECT_NEAR(speed, orbit_speed(20, config.limits), 1e-9);
  EXPECT_DOUBLE_EQ(speed, 3.0);  // sqrt(0.8·4·20) = 8 > 3: the speed limit binds
  EXPECT_NEAR(std::hypot(d().state().x, d().state().y), 20.0, 1e-9);
}

TEST_F(Motion, HoverWithDurationEndsAfterIt) {
  airborne(5);
  double t0 = loop.now();
  test::Result r = run("Hover", {7.5});
  EXPECT_EQ(r.end.outcome, Outcome::succeeded);
  EXPECT_DOUBLE_EQ(r.t - t0, 7.5);
  EXPECT_DOUBLE_EQ(d().state().z, 5.0);
}

TEST_F(Motion, HoverWithoutDurationRunsUntilPreempted) {
  airborne(5);
  auto hover = start("Hover");
  loop.run_until(loop.now() + 600);  // a long time, but less than the battery lasts
  EXPECT_FALSE(hover->ended);
  test::Result fly = run("FlyByX", {2});
  EXPECT_EQ(hover->end.outcome, Outcome::preempted);
  EXPECT_EQ(fly.end.outcome, Outcome::succeeded);
}

TEST_F(Motion, HoverStopsAMovingDroneWhereItIs) {
  airborne(5);
  auto fly = start("FlyByX", {100});
  loop.run_until(loop.now() + 5);
  double x = d().state().x;
  test::Result hover = run("Hover", {10});
  EXPECT_EQ(fly->end.outcome, Outcome::preempted);
  EXPECT_EQ(hover.end.outcome, Outcome::succeeded);
  EXPECT_TRUE(d().velocity() == fleet::Vec3{});
  EXPECT_NEAR(d().state().x, x, 0.01);  // braked, overshot a little, came back
}

TEST_F(Motion, ReturnHomeFliesBackAndLandsAtHome) {
  config.home = {5, -5, 0};
  airborne(10);
  ASSERT_EQ(run("FlyTo", {40, 30, 15}).end.outcome, Outcome::succeeded);
  test::Result r = run("ReturnHome");
  EXPECT_EQ(r.end.outcome, Outcome::succeeded);
  mid::DroneState s = d().state();
  EXPECT_DOUBLE_EQ(s.x, 5.0);
  EXPECT_DOUBLE_EQ(s.y, -5.0);
  EXPECT_DOUBLE_EQ(s.z, 0.0);
  EXPECT_TRUE(s.landed);
}

TEST_F(Motion, CancelEndsActionCancelled) {
  airborne(5);
  auto fly = start("FlyByX", {100});
  loop.run_until(loop.now() + 4);
  EXPECT_TRUE(d().cancel(fly->id));
  EXPECT_FALSE(fly->ended);  // reported through the loop, not inside cancel()
  loop.run_until(loop.now() + 10);
  EXPECT_EQ(fly->end.outcome, Outcome::cancelled);
  EXPECT_LT(d().state().x, 50.0);  // it stopped instead of flying on
  EXPECT_TRUE(d().velocity() == fleet::Vec3{});
  EXPECT_FALSE(d().cancel(fly->id));  // ended: the outcome stands
}

TEST_F(Motion, CancelAfterSuccessChangesNothing) {
  airborne(5);
  test::Result fly = run("FlyByX", {1});
  EXPECT_FALSE(d().cancel(fly.id));
  loop.run_until(loop.now() + 1);
  EXPECT_EQ(fly.end.outcome, Outcome::succeeded);
}

TEST_F(Motion, ProgressRisesDuringAFlight) {
  airborne(5);
  auto fly = start("FlyByX", {50});
  EXPECT_EQ(d().progress(fly->id), 0.0);
  loop.run_until(loop.now() + 3);
  double mid_flight = d().progress(fly->id).value();
  EXPECT_GT(mid_flight, 0.0);
  EXPECT_LT(mid_flight, 1.0);
  run_until_ended(*fly);
  EXPECT_FALSE(d().progress(fly->id).has_value());
  auto orbit = start("Orbit");
  EXPECT_FALSE(d().progress(orbit->id).has_value());
}

TEST_F(Motion, TimeoutFailsAction) {
  config.timeouts_s["FlyTo"] = 2.0;
  airborne(5);
  double t0 = loop.now();
  test::Result r = run("FlyTo", {500, 0, 5});
  EXPECT_EQ(r.end.outcome, Outcome::failed);
  EXPECT_EQ(r.end.reason, "timed out after 2.0 s");
  EXPECT_EQ(r.end.failure, mid::FailureReason::timed_out);
  EXPECT_DOUBLE_EQ(r.t - t0, 2.0);
  loop.run_until(loop.now() + 10);
  EXPECT_TRUE(d().velocity() == fleet::Vec3{});  // holds where the deadline caught it
  EXPECT_LT(d().state().x, 20.0);
}

TEST_F(Motion, DerivedTimeoutDoesNotFailANormalFlight) {
  airborne(5);
  EXPECT_EQ(run("FlyTo", {2000, 0, 100}).end.outcome, Outcome::succeeded);
}

}  // namespace
}  // namespace eamos::sim

namespace eamos::sim::test {
namespace {

// An autopilot told to land while flying brakes and lands where it comes to rest; it does
// not fly back to where the command found it.
TEST_F(SimTest, LandWhileMovingLandsWhereTheDroneComesToRest) {
  run("Arm");
  run("Takeoff", {5});
  auto fly = start("FlyByX", {40});
  loop.run_until(loop.now() + 5.0);  // well under way east at cruise speed
  double x_at_land = d().state().x;
  Result land = run("Land");
  EXPECT_EQ(land.end.outcome, mid::Outcome::succeeded);
  EXPECT_EQ(fly->end.outcome, mid::Outcome::preempted);
  EXPECT_GT(d().state().x, x_at_land + 1.0);  // braking distance ahead, not back
  EXPECT_TRUE(d().state().landed);
}

}  // namespace
}  // namespace eamos::sim::test
