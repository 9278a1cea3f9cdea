// The fleet's safety rules on a MAVLink vehicle (the simulated PX4-like vehicle over loopback
// UDP, real time sped up 4×): the same guard as the simulator's, in the Uniform Space, plus
// the adapter's setpoint pacing for the site's speed limits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "flight.h"

namespace eamos::mavlink_adapter {
namespace {

using test::Flight;
using test::kSpeed;

fleet::Geofence square(double half) {
  fleet::Geofence g;
  g.polygon = {{-half, -half}, {half, -half}, {half, half}, {-half, half}};
  g.max_altitude_m = 10.0;
  return g;
}

TEST(MavlinkSiteLimits, ATargetOutsideTheFenceIsRefusedBeforeTheVehicleMoves) {
  test::VehicleThread vehicle(25471, 1, kSpeed);
  Flight f(25471, {}, [](fleet::DroneSettings& s) { s.site.geofence = square(10); });
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  ASSERT_EQ(f.fly("Takeoff", {3}).outcome, mid::Outcome::succeeded);
  double x = f.drone->state().x;
  mid::ActionEnd e = f.fly("FlyTo", {25, 0, 3});
  EXPECT_EQ(e.outcome, mid::Outcome::failed);
  EXPECT_EQ(e.failure, mid::FailureReason::refused);
  EXPECT_NE(e.reason.find("Drone1 FlyTo: target (25.0, 0.0, 3.0) is outside its polygon"), std::string::npos)
      << e.reason;
  e = f.fly("FlyByZ", {9});
  EXPECT_NE(e.reason.find("above its max_altitude 10.0 m"), std::string::npos) << e.reason;
  EXPECT_NEAR(f.drone->state().x, x, 0.3);  // no setpoint toward either target was sent
}

// The vehicle's own hover wanders 3 m east after its takeoff (as PX4 SITL's did), out of a
// fence 2 m from home: the adapter sees it in the next position report (10 Hz, at most 1 m
// further at the vehicle's 10 m/s: caught at x < 3) and lands it.
TEST(MavlinkSiteLimits, AVehicleThatWandersOutOfItsFenceIsLandedByItsFailsafe) {
  sim_vehicle::VehicleOptions o;
  o.hover_wander_east_m = 3.0;
  test::VehicleThread vehicle(25472, kSpeed, o);
  Flight f(25472, {}, [](fleet::DroneSettings& s) { s.site.geofence = square(2); });
  ASSERT_TRUE(f.drone) << f.created.message;
  std::optional<mid::ActionEnd> fault;
  f.drone->set_fault_sink([&](const mid::ActionEnd& e) { fault = e; });
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  mid::ActionEnd takeoff = f.fly("Takeoff", {3});
  // The wander may begin before the adapter has judged the takeoff done: then the takeoff
  // carries the fault, else the drone reports it itself.
  if (takeoff.outcome == mid::Outcome::succeeded) {
    for (int i = 0; i < 40 && !fault; ++i) f.loop.run_until(f.loop.now() + 0.25);
    ASSERT_TRUE(fault);
    takeoff = *fault;
  }
  EXPECT_EQ(takeoff.failure, mid::FailureReason::vehicle_fault);
  EXPECT_NE(takeoff.reason.find("Drone1 left its geofence at (2."), std::string::npos) << takeoff.reason;
  for (int i = 0; i < 120 && !f.drone->state().landed; ++i) f.loop.run_until(f.loop.now() + 0.25);
  EXPECT_TRUE(f.drone->state().landed);
  EXPECT_EQ(f.fly("Takeoff", {3}).reason, std::string("failsafe active (failsafe: land)"));
}

// The vehicle would fly 10 m/s; the site allows 1 m/s: the streamed setpoint moves at that.
// The vehicle trails it as it starts and catches up after: over a second it flew up to
// 1.35 m/s here (docs/adapters.md, "Site speed limits").
TEST(MavlinkSiteLimits, TheSitesMaxSpeedPacesTheSetpointsTheVehicleChases) {
  test::VehicleThread vehicle(25473, 1, kSpeed);
  Flight f(25473, {}, [](fleet::DroneSettings& s) { s.site.max_speed_mps = 1.0; });
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  ASSERT_EQ(f.fly("Takeoff", {3}).outcome, mid::Outcome::succeeded);
  std::vector<mid::DroneState> track;
  f.drone->subscribe([&](const mid::DroneState& s) { track.push_back(s); });
  double start = f.loop.now();
  ASSERT_EQ(f.fly("FlyByX", {4}).outcome, mid::Outcome::succeeded);
  EXPECT_GT(f.loop.now() - start, 3.5);  // 4 m at 1 m/s, not at 10 m/s
  double fastest = 0.0;
  for (std::size_t i = 0, j = 0; i < track.size(); ++i) {
    while (track[i].t - track[j].t > 1.0) ++j;  // over about a second of reports
    if (track[i].t - track[j].t > 0.5)
      fastest = std::max(fastest, std::hypot(track[i].x - track[j].x, track[i].y - track[j].y) / (track[i].t - track[j].t));
  }
  EXPECT_LE(fastest, 1.5);
}

}  // namespace
}  // namespace eamos::mavlink_adapter
