// The site's rules on requests, shared by every adapter: which targets the geofence refuses,
// and the limits a drone flies with.
#include "mid/site_limits.h"

#include <gtest/gtest.h>

namespace eamos::mid {
namespace {

fleet::DroneSettings fenced() {
  fleet::DroneSettings s;
  s.name = "Drone1";
  fleet::Geofence g;
  // An L: the square (0..20, 0..20) without its north-east quarter.
  g.polygon = {{0, 0}, {20, 0}, {20, 10}, {10, 10}, {10, 20}, {0, 20}};
  g.min_altitude_m = 2;
  g.max_altitude_m = 30;
  s.site.geofence = g;
  s.home = {5, 5, 0};
  return s;
}

std::string refusal(const ActionRequest& r, fleet::Vec3 at, bool landed = false) {
  fleet::DroneSettings s = fenced();
  const fleet::DroneType quad = fleet::generic_multirotor("Quad");  // owns the spec below
  const fleet::ActionSpec* spec = quad.find_action(r.name);
  return uniform_refusal(r, *spec, {true, landed, at, ""}, s);
}

TEST(SiteRules, ATargetInsideTheFenceIsAccepted) {
  EXPECT_EQ(refusal({"FlyTo", {15, 5, 10}}, {5, 5, 10}), "");
  EXPECT_EQ(refusal({"FlyByZ", {15}}, {5, 5, 10}), "");
}

TEST(SiteRules, ATargetOutsideTheFenceOrItsBandIsRefusedNamingTargetAndRule) {
  EXPECT_EQ(refusal({"FlyTo", {15, 15, 10}}, {5, 5, 10}),
            "Drone1 FlyTo: target (15.0, 15.0, 10.0) is outside its polygon of 6 corners (x 0.0 to 20.0, y 0.0 "
            "to 20.0) of Drone1's geofence; keep the target inside it, or widen `geofence:` in the fleet file");
  EXPECT_NE(refusal({"FlyByZ", {25}}, {5, 5, 10}).find("is above its max_altitude 30.0 m"), std::string::npos);
  EXPECT_NE(refusal({"FlyByZ", {-9}}, {5, 5, 10}).find("is below its min_altitude 2.0 m"), std::string::npos);
}

TEST(SiteRules, AStraightPathThatLeavesAConcaveFenceIsRefused) {
  // (15, 5) to (5, 18): both inside the L, the line between them cuts the missing quarter.
  std::string why = refusal({"FlyTo", {5, 18, 10}}, {15, 5, 10});
  EXPECT_NE(why.find("the straight path from (15.0, 5.0, 10.0) to it leaves"), std::string::npos) << why;
}

TEST(SiteRules, APathAlongTheFenceOrThroughItsCornerStaysInside) {
  EXPECT_EQ(refusal({"FlyTo", {5, 15, 10}}, {15, 5, 10}), "");  // touches the inner corner (10, 10)
  EXPECT_EQ(refusal({"FlyTo", {10, 20, 10}}, {10, 0, 10}), "");  // along the edge x = 10
}

TEST(SiteRules, TakeoffStartsBelowMinAltitudeButNotAboveMaxAltitude) {
  EXPECT_EQ(refusal({"Takeoff", {5}}, {5, 5, 0}, true), "");
  EXPECT_NE(refusal({"Takeoff", {40}}, {5, 5, 0}, true).find("above its max_altitude"), std::string::npos);
}

TEST(SiteRules, AnOrbitWhoseCircleLeavesTheFenceIsRefusedLandAndReturnHomeNever) {
  EXPECT_NE(refusal({"Orbit", {8}}, {5, 5, 10}).find("Drone1 Orbit: its circle of radius 8.0 m"), std::string::npos);
  EXPECT_EQ(refusal({"Orbit", {3}}, {5, 5, 10}), "");
  EXPECT_EQ(refusal({"Land", {}}, {15, 15, 10}), "");
  EXPECT_EQ(refusal({"ReturnHome", {}}, {15, 15, 10}), "");
}

TEST(SiteRules, TheSitesSpeedsCapTheVehiclesAndNeverRaiseThem) {
  fleet::DroneSettings s;
  s.limits.max_speed_mps = 4;
  s.site.max_speed_mps = 6;
  s.site.max_climb_mps = 1;
  fleet::Limits l = flight_limits(s);
  EXPECT_EQ(l.max_speed_mps, 4);
  EXPECT_EQ(l.max_climb_mps, 1);
  EXPECT_EQ(l.max_descent_mps, s.limits.max_descent_mps);
}

}  // namespace
}  // namespace eamos::mid
