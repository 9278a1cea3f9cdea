// The site's rules in the simulator: its limits capped by the site's speeds, the fleet's
// gust that pushes a drone, and the failsafe a drone outside its fence commands itself.
#include <gtest/gtest.h>

#include <optional>

#include "helpers.h"

namespace eamos::sim {
namespace {

using mid::Outcome;

class SimSiteLimits : public test::SimTest {
 protected:
  void fence(double half) {
    fleet::Geofence g;
    g.polygon = {{-half, -half}, {half, -half}, {half, half}, {-half, half}};
    config.site.geofence = g;
  }
};

TEST_F(SimSiteLimits, TheSitesSpeedsCapTheDronesOwn) {
  config.site.max_speed_mps = 2.5;
  config.site.max_climb_mps = 0.5;
  airborne(1);
  double top = 0.0;
  auto fly = start("FlyTo", {20, 0, 1});
  while (!fly->ended) {
    loop.run_until(loop.now() + 0.05);
    top = std::max(top, std::hypot(d().velocity().x, d().velocity().y));
  }
  EXPECT_DOUBLE_EQ(top, 2.5);  // the vehicle's own is 10 m/s
}

TEST_F(SimSiteLimits, AGustPushesTheDroneOnlyInItsWindow) {
  config.gust = fleet::Gust{.at_s = 20, .for_s = 2, .velocity = {3, -1, 0}};
  airborne(5);  // done before 20 s
  double x = d().state().x;
  loop.run_until(30);
  EXPECT_NEAR(d().state().x - x, 6.0, 1e-6);
  EXPECT_NEAR(d().state().y, -2.0, 1e-6);
}

TEST_F(SimSiteLimits, ADroneOutsideItsFenceCommandsItsFailsafeBeforeReportingIt) {
  fence(10);
  config.failsafe = fleet::Failsafe::hover;
  config.gust = fleet::Gust{.at_s = 10, .for_s = 30, .velocity = {5, 0, 0}};
  airborne(5);
  std::optional<mid::ActionEnd> fault;
  std::string mode_at_fault;
  d().set_fault_sink([&](const mid::ActionEnd& e) {
    fault = e;
    mode_at_fault = d().state().mode;  // the failsafe was already commanded
  });
  loop.run_until(40);
  ASSERT_TRUE(fault);
  EXPECT_EQ(fault->outcome, Outcome::failed);
  EXPECT_EQ(fault->failure, mid::FailureReason::vehicle_fault);
  EXPECT_EQ(fault->reason.rfind("Drone1 left its geofence at (10.", 0), 0u) << fault->reason;
  EXPECT_EQ(mode_at_fault.rfind("failsafe", 0), 0u) << mode_at_fault;
  EXPECT_EQ(run("FlyTo", {0, 0, 5}).end.reason, "failsafe active (failsafe: hover)");
}

TEST_F(SimSiteLimits, TheRunningActionCarriesTheBreachAndNoSeparateFaultComes) {
  fence(10);
  config.gust = fleet::Gust{.at_s = 10, .for_s = 30, .velocity = {5, 0, 0}};
  airborne(5);
  bool fault = false;
  d().set_fault_sink([&](const mid::ActionEnd&) { fault = true; });
  test::Result hover = run("Hover", {60});
  EXPECT_EQ(hover.end.outcome, Outcome::failed);
  EXPECT_NE(hover.end.reason.find("left its geofence"), std::string::npos) << hover.end.reason;
  loop.run_until(loop.now() + 1);
  EXPECT_FALSE(fault);
}

}  // namespace
}  // namespace eamos::sim
