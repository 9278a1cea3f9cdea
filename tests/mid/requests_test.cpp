// Request checks and goal positions: shared by every adapter, consistent with the catalog.
#include "mid/requests.h"

#include <gtest/gtest.h>

#include <cmath>

#include "mid/vec.h"

namespace eamos::mid {
namespace {

TEST(Requests, CapabilityOfTheTypeIsAccepted) {
  fleet::DroneType t = fleet::generic_multirotor("Quad");
  RequestCheck c = check_request({"FlyTo", {1, 2, 3}}, t);
  ASSERT_NE(c.spec, nullptr);
  EXPECT_EQ(c.spec->action_class, fleet::ActionClass::motion);
  EXPECT_EQ(check_request({"Sensor8", {}}, t).spec->action_class, fleet::ActionClass::payload);
}

TEST(Requests, ActionTheTypeLacksIsRefusedNamingTheType) {
  fleet::DroneType t = fleet::generic_multirotor("Quad");
  std::erase_if(t.actions, [](const fleet::ActionSpec& a) { return a.name == "Orbit"; });
  ASSERT_EQ(t.find_action("Orbit"), nullptr);
  RequestCheck c = check_request({"Orbit", {}}, t);
  EXPECT_EQ(c.spec, nullptr);
  EXPECT_EQ(c.error, "type 'Quad' has no action 'Orbit'");
  EXPECT_NE(check_request({"Sensor9", {}}, t).error, "");
}

TEST(Requests, WrongNumberOfArgumentsIsRefused) {
  RequestCheck c = check_request({"FlyTo", {1, 2}}, fleet::generic_multirotor("Quad"));
  EXPECT_EQ(c.spec, nullptr);
  EXPECT_EQ(c.error, "FlyTo takes (x_m, y_m, z_m), not 2 arguments");
}

TEST(Requests, NonFiniteArgumentIsRefused) {
  RequestCheck c = check_request({"FlyByX", {NAN}}, fleet::generic_multirotor("Quad"));
  EXPECT_EQ(c.spec, nullptr);
  EXPECT_NE(c.error.find("finite"), std::string::npos);
}

TEST(Requests, GoalPositionsFollowTheCatalogMeaning) {
  fleet::Vec3 p{1, 2, 3}, home{10, 20, 0.5};
  EXPECT_TRUE(*goal_position({"Takeoff", {4}}, p, home) == (fleet::Vec3{1, 2, 4.5}));
  EXPECT_TRUE(*goal_position({"Land", {}}, p, home) == (fleet::Vec3{1, 2, 0.5}));
  EXPECT_TRUE(*goal_position({"FlyTo", {7, 8, 9}}, p, home) == (fleet::Vec3{7, 8, 9}));
  EXPECT_TRUE(*goal_position({"FlyBy", {1, 1, 1}}, p, home) == (fleet::Vec3{2, 3, 4}));
  EXPECT_TRUE(*goal_position({"FlyByX", {-5}}, p, home) == (fleet::Vec3{-4, 2, 3}));
  EXPECT_TRUE(*goal_position({"FlyByY", {5}}, p, home) == (fleet::Vec3{1, 7, 3}));
  EXPECT_TRUE(*goal_position({"FlyByZ", {5}}, p, home) == (fleet::Vec3{1, 2, 8}));
  EXPECT_TRUE(*goal_position({"ReturnHome", {}}, p, home) == home);
  EXPECT_FALSE(goal_position({"Orbit", {}}, p, home).has_value());
  EXPECT_FALSE(goal_position({"TakePicture", {}}, p, home).has_value());
}

}  // namespace
}  // namespace eamos::mid
