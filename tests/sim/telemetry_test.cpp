// The property broker of a simulated drone: telemetry at the step rate while moving, on every
// change of armed, landed or pictures, slowly while armed and still; never inline.
#include <gtest/gtest.h>

#include "helpers.h"

namespace eamos::sim {
namespace {

using mid::Outcome;

class Telemetry : public test::SimTest {
 protected:
  std::vector<mid::DroneState> seen;
  void record() {
    d().subscribe([this](const mid::DroneState& s) { seen.push_back(s); });
  }
};

TEST_F(Telemetry, PublishesAtTheStepRateWhileMoving) {
  airborne(5);
  record();
  auto fly = start("FlyByX", {100});
  double t0 = loop.now();
  loop.run_until(t0 + 2.0);
  ASSERT_EQ(seen.size(), 40u);  // 20 Hz for 2 s
  EXPECT_DOUBLE_EQ(seen[0].t, t0 + 0.05);
  for (size_t i = 1; i < seen.size(); ++i) {
    EXPECT_NEAR(seen[i].t - seen[i - 1].t, 0.05, 1e-9);
    EXPECT_GT(seen[i].x, seen[i - 1].x);
  }
}

TEST_F(Telemetry, PublishesOnArmedAndLandedChanges) {
  record();
  run("Arm");
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_TRUE(seen[0].armed);
  EXPECT_TRUE(seen[0].landed);
  seen.clear();
  run("Takeoff", {2});
  ASSERT_FALSE(seen.empty());
  EXPECT_FALSE(seen.front().landed);  // the first step leaves the ground and says so
  run("Land");
  EXPECT_TRUE(seen.back().landed);
  EXPECT_DOUBLE_EQ(seen.back().z, 0.0);
  seen.clear();
  run("Disarm");
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_FALSE(seen[0].armed);
}

TEST_F(Telemetry, SubscribeAndStartNeverPublishInline) {
  record();
  start("Arm");
  EXPECT_TRUE(seen.empty());
  loop.run_until(0.5);  // not until idle: an armed, subscribed drone publishes every second
  EXPECT_EQ(seen.size(), 1u);
}

TEST_F(Telemetry, ArmedAndStillPublishesSlowlyForTheBattery) {
  airborne(5);
  record();
  double t0 = loop.now();
  loop.run_until(t0 + 10);
  ASSERT_EQ(seen.size(), 10u);  // 1 Hz
  EXPECT_LT(seen.back().battery, seen.front().battery);
}

TEST_F(Telemetry, UnsubscribedDroneHoveringRunsNoEvents) {
  airborne(5);
  auto hover = start("Hover");
  loop.run_until(loop.now() + 1);
  std::uint64_t events = loop.events_run();
  loop.run_until(loop.now() + 600);
  EXPECT_EQ(loop.events_run(), events);
  EXPECT_EQ(loop.size(), 1u);  // only the battery's "empty at" timer waits, far ahead
  EXPECT_FALSE(hover->ended);
}

TEST_F(Telemetry, UnsubscribeStopsTheCalls) {
  airborne(5);
  mid::SubscriptionId id = d().subscribe([this](const mid::DroneState& s) { seen.push_back(s); });
  loop.run_until(loop.now() + 3);
  size_t before = seen.size();
  d().unsubscribe(id);
  std::uint64_t events = loop.events_run();
  loop.run_until(loop.now() + 3);
  EXPECT_EQ(seen.size(), before);
  EXPECT_EQ(loop.events_run(), events);
}

}  // namespace
}  // namespace eamos::sim
