// Mover and LocationValidator: the Uniform Space's motion utilities. Every step keeps the
// platform's speed, climb, descent and acceleration limits, and a move ends on the target.
#include "mid/mover.h"

#include <gtest/gtest.h>

#include "mid/location_validator.h"
#include "mid/vec.h"

namespace eamos::mid {
namespace {

using fleet::Vec3;

constexpr double kDt = 0.05;

fleet::Limits limits() {
  fleet::Limits l;
  l.max_speed_mps = 5;
  l.max_climb_mps = 2;
  l.max_descent_mps = 1;
  l.max_accel_mps2 = 3;
  return l;
}

// Moves until arrival; checks the limits on every step; returns the steps taken.
int fly(Kinematics& k, Vec3 target, const fleet::Limits& l, int max_steps = 100000) {
  for (int n = 1; n <= max_steps; ++n) {
    Vec3 before = k.velocity;
    bool arrived = move_toward(k, target, l, kDt);
    if (arrived) return n;
    EXPECT_LE(horizontal_norm(k.velocity), l.max_speed_mps + 1e-9);
    EXPECT_LE(k.velocity.z, l.max_climb_mps + 1e-9);
    EXPECT_GE(k.velocity.z, -l.max_descent_mps - 1e-9);
    EXPECT_LE(norm(k.velocity - before), l.max_accel_mps2 * kDt + 1e-9);
  }
  ADD_FAILURE() << "never arrived";
  return max_steps;
}

TEST(Mover, EndsExactlyOnTargetAtRest) {
  Kinematics k;
  Vec3 target{30, -20, 10};
  fly(k, target, limits());
  EXPECT_TRUE(k.position == target);
  EXPECT_TRUE(k.velocity == Vec3{});
}

TEST(Mover, HorizontalMoveTakesAtLeastDistanceOverMaxSpeed) {
  Kinematics k;
  int steps = fly(k, {100, 0, 0}, limits());
  EXPECT_GE(steps * kDt, 100.0 / 5.0);
  // ... and not much longer: accelerating and braking at 3 m/s² cost about 5/3 s.
  EXPECT_LE(steps * kDt, 100.0 / 5.0 + 5.0 / 3.0 + 0.2);
}

TEST(Mover, ClimbAndDescentUseTheirOwnLimits) {
  Kinematics k;
  int up = fly(k, {0, 0, 20}, limits());
  EXPECT_GE(up * kDt, 20.0 / 2.0);
  int down = fly(k, {0, 0, 0}, limits());
  EXPECT_GE(down * kDt, 20.0 / 1.0);
}

TEST(Mover, BrakesWithoutOvershoot) {
  Kinematics k;
  double last = 1e9;
  for (int n = 0; n < 10000; ++n) {
    if (move_toward(k, {40, 0, 0}, limits(), kDt)) break;
    EXPECT_LE(k.position.x, 40.0);
    EXPECT_LT(40.0 - k.position.x, last + 1e-12);
    last = 40.0 - k.position.x;
  }
  EXPECT_DOUBLE_EQ(k.position.x, 40.0);
}

TEST(Mover, TurnsSmoothlyWhenTheTargetChangesMidFlight) {
  Kinematics k;
  for (int n = 0; n < 100; ++n) move_toward(k, {100, 0, 0}, limits(), kDt);
  ASSERT_GT(k.velocity.x, 4.0);
  fly(k, {0, 50, 5}, limits());  // checks every step's acceleration
  EXPECT_TRUE(k.position == (Vec3{0, 50, 5}));
}

TEST(Mover, TargetWhereItIsArrivesAtOnce) {
  Kinematics k{{1, 2, 3}, {}};
  EXPECT_TRUE(move_toward(k, {1, 2, 3}, limits(), kDt));
}

TEST(Mover, LimitedVelocityKeepsDirection) {
  Vec3 v = limited_velocity({3, 4, 10}, 100.0, limits());
  EXPECT_NEAR(v.z, 2.0, 1e-12);  // climb binds
  EXPECT_NEAR(v.x / v.y, 0.75, 1e-12);
  EXPECT_NEAR(horizontal_norm(v) / v.z, 0.5, 1e-12);
}

TEST(LocationValidator, ReachedWithinHorizontalAndVerticalTolerance) {
  LocationValidator v({10, 0, 5}, {0.5, 0.25});
  EXPECT_TRUE(v.reached({10, 0, 5}));
  EXPECT_TRUE(v.reached({10, 0.5, 5.25}));  // bounds inclusive
  EXPECT_FALSE(v.reached({10.5, 0.5, 5}));   // 0.71 m away
  EXPECT_FALSE(v.reached({10, 0, 5.3}));     // too high, though right above
}

}  // namespace
}  // namespace eamos::mid
