// Action timeouts: expected duration at the platform limits × margin + slack; the fleet
// file's timeouts replace them; Hover() and Orbit() never time out.
#include "mid/timeouts.h"

#include <gtest/gtest.h>

#include <cmath>

namespace eamos::mid {
namespace {

fleet::DroneSettings drone() {
  fleet::DroneSettings d;
  d.name = "Drone1";
  d.home = {0, 0, 0};
  d.limits.max_speed_mps = 10;
  d.limits.max_climb_mps = 2;
  d.limits.max_descent_mps = 1;
  return d;
}

TEST(Timeouts, DerivedFromDistanceOverSpeed) {
  ActionRequest fly{"FlyTo", {100, 0, 5}};
  EXPECT_DOUBLE_EQ(expected_duration(fly, {0, 0, 5}, drone()), 10.0);
  EXPECT_DOUBLE_EQ(action_timeout(fly, {0, 0, 5}, drone()),
                   10.0 * kTimeoutMargin + kTimeoutSlack_s);
}

TEST(Timeouts, ClimbUsesMaxClimbAndDescentUsesMaxDescent) {
  EXPECT_DOUBLE_EQ(expected_duration({"Takeoff", {10}}, {0, 0, 0}, drone()), 5.0);
  EXPECT_DOUBLE_EQ(expected_duration({"Land", {}}, {3, 4, 10}, drone()), 10.0);
  EXPECT_DOUBLE_EQ(expected_duration({"FlyByZ", {-4}}, {0, 0, 10}, drone()), 4.0);
}

TEST(Timeouts, ReturnHomeAddsFlightBackAndDescent) {
  // 50 m back at 10 m/s, then 8 m down at 1 m/s.
  EXPECT_DOUBLE_EQ(expected_duration({"ReturnHome", {}}, {30, 40, 8}, drone()), 13.0);
}

TEST(Timeouts, HoverWithDurationExpectsThatDuration) {
  EXPECT_DOUBLE_EQ(expected_duration({"Hover", {7}}, {}, drone()), 7.0);
}

TEST(Timeouts, PayloadAndSystemActionsGetTheSlack) {
  EXPECT_DOUBLE_EQ(action_timeout({"TakePicture", {}}, {}, drone()), kTimeoutSlack_s);
  EXPECT_DOUBLE_EQ(action_timeout({"Arm", {}}, {}, drone()), kTimeoutSlack_s);
}

TEST(Timeouts, FleetFileValueReplacesTheDerivedOne) {
  fleet::DroneSettings d = drone();
  d.timeouts_s["FlyTo"] = 3.0;
  EXPECT_DOUBLE_EQ(action_timeout({"FlyTo", {1000, 0, 5}}, {0, 0, 5}, d), 3.0);
  EXPECT_DOUBLE_EQ(action_timeout({"FlyByX", {100}}, {0, 0, 5}, d), 10.0 * 1.5 + 10.0);
}

TEST(Timeouts, EndlessActionsHaveNoTimeoutEvenWhenTheFleetSetsOne) {
  fleet::DroneSettings d = drone();
  d.timeouts_s["Orbit"] = 3.0;
  d.timeouts_s["Hover"] = 3.0;
  EXPECT_TRUE(std::isinf(action_timeout({"Orbit", {}}, {}, d)));
  EXPECT_TRUE(std::isinf(action_timeout({"Orbit", {10}}, {}, d)));
  EXPECT_TRUE(std::isinf(action_timeout({"Hover", {}}, {}, d)));
  EXPECT_DOUBLE_EQ(action_timeout({"Hover", {60}}, {}, d), 3.0);  // Hover(s) does end
}

}  // namespace
}  // namespace eamos::mid
