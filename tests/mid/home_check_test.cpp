#include "mid/home_check.h"

#include <gtest/gtest.h>

#include <cmath>

namespace eamos::mid {
namespace {

// Metres to degrees near 47.4° N: a vehicle `east`, `north` metres from the reference.
GlobalFix at(double east, double north) {
  constexpr double lat0 = 47.397742, lon0 = 8.545594, r = 6'371'000.0, rad = M_PI / 180.0;
  return {lat0 + north / r / rad, lon0 + east / (r * std::cos(lat0 * rad)) / rad};
}

TEST(HomeCheck, VehiclesStandingAsTheirHomesSayPass) {
  std::vector<HomeReport> d = {{"A", {10, 20, 0}, at(0, 0)}, {"B", {10, 25, 0}, at(0.5, 5.2)}, {"C", {0, 20, 0}, at(-10, 0)}};
  EXPECT_EQ(compare_homes(d), "");
}

TEST(HomeCheck, ThreeVehiclesOnOneSpotWithHomesFiveMetresApartNameBothPositions) {
  std::vector<HomeReport> d = {{"A", {0, 0, 0}, at(0, 0)}, {"B", {0, 5, 0}, at(0, 0)}, {"C", {0, 10, 0}, at(0, 0)}};
  std::string why = compare_homes(d);
  EXPECT_NE(why.find("B stands at [0.0, 0.0] in the mission frame (lat 47.3977420, lon 8.5455940; measured from A at its home "
                     "[0.0, 0.0]), but its home in the fleet file is [0.0, 5.0]: 5.0 m apart, more than home_tolerance "
                     "3 m; place the vehicle at its home, or write the home where it stands (home: [0.0, 0.0, 0])"),
            std::string::npos)
      << why;
  EXPECT_NE(why.find("C stands at [0.0, 0.0]"), std::string::npos) << why;
  EXPECT_EQ(why.find("A stands"), std::string::npos) << why;
}

TEST(HomeCheck, TheOneMisplacedVehicleIsNamedNotTheOthers) {
  // A is the first declared, but it is the one out of place: B and C agree with each other.
  std::vector<HomeReport> d = {{"A", {0, 0, 0}, at(8, 0)}, {"B", {0, 5, 0}, at(0, 5)}, {"C", {0, 10, 0}, at(0, 10)}};
  std::string why = compare_homes(d);
  EXPECT_NE(why.find("A stands at [8.0, 0.0]"), std::string::npos) << why;
  EXPECT_EQ(why.find("B stands"), std::string::npos) << why;
  EXPECT_EQ(why.find("C stands"), std::string::npos) << why;
}

TEST(HomeCheck, TheFleetsToleranceDecides) {
  std::vector<HomeReport> d = {{"A", {0, 0, 0}, at(0, 0), 3.0}, {"B", {0, 5, 0}, at(0, 1), 3.0}};
  EXPECT_NE(compare_homes(d), "");
  for (auto& r : d) r.tolerance_m = 4.5;
  EXPECT_EQ(compare_homes(d), "");
}

TEST(HomeCheck, DronesWithoutAGlobalPositionAreLeftOut) {
  std::vector<HomeReport> d = {{"A", {0, 0, 0}, at(0, 0)}, {"Sim", {0, 50, 0}, std::nullopt}};
  EXPECT_EQ(compare_homes(d), "");
}

}  // namespace
}  // namespace eamos::mid
