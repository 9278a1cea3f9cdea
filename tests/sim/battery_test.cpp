// The battery drains per phase (constants in sim/battery.h): nothing disarmed, a little armed
// on the ground, more in the air; an empty battery in the air forces a landing.
#include <gtest/gtest.h>

#include <cmath>

#include "helpers.h"
#include "sim/battery.h"

namespace eamos::sim {
namespace {

using mid::Outcome;

class BatteryDrain : public test::SimTest {};

TEST_F(BatteryDrain, DisarmedDroneDoesNotDrain) {
  config.battery_percent = 80;
  make();
  loop.run_until(3600);
  EXPECT_DOUBLE_EQ(d().state().battery, 80.0);
}

TEST_F(BatteryDrain, ArmedOnTheGroundDrainsTheIdleRate) {
  ASSERT_EQ(run("Arm").end.outcome, Outcome::succeeded);
  loop.run_until(100);
  EXPECT_NEAR(d().state().battery, 100.0 - 100 * kDrainArmedOnGround, 1e-9);
}

TEST_F(BatteryDrain, FlyingDrainsTheAirborneRate) {
  airborne(5);
  double b0 = d().state().battery;
  double t0 = loop.now();
  loop.run_until(t0 + 200);
  EXPECT_NEAR(b0 - d().state().battery, 200 * kDrainAirborne, 1e-9);
  EXPECT_GT(kDrainAirborne, kDrainArmedOnGround);
}

TEST_F(BatteryDrain, EmptyBatteryInTheAirFailsMotionAndLands) {
  config.battery_percent = 2;  // 20 s of flight
  airborne(10);
  auto orbit = start("Orbit");
  run_until_ended(*orbit, 60);
  EXPECT_EQ(orbit->end.outcome, Outcome::failed);
  EXPECT_EQ(orbit->end.reason, "battery empty");
  EXPECT_EQ(orbit->end.failure, mid::FailureReason::vehicle_fault);
  EXPECT_EQ(orbit->end.detail, "battery at 0.0 %");
  loop.run_until(loop.now() + 60);
  mid::DroneState s = d().state();
  EXPECT_TRUE(s.landed);
  EXPECT_FALSE(s.armed);
  EXPECT_DOUBLE_EQ(s.battery, 0.0);
  EXPECT_EQ(run("Arm").end.outcome, Outcome::failed);
}

TEST(Battery, ChargeIsExactBetweenRateChanges) {
  Battery b(50, 0);
  b.set_rate(10, 0.5);
  EXPECT_DOUBLE_EQ(b.at(20), 45);
  EXPECT_DOUBLE_EQ(b.empty_at(), 110);
  b.set_rate(20, 0.0);
  EXPECT_DOUBLE_EQ(b.at(1000), 45);
  EXPECT_TRUE(std::isinf(b.empty_at()));
  EXPECT_DOUBLE_EQ(drain_rate(false, false), kDrainDisarmed);
}

}  // namespace
}  // namespace eamos::sim
