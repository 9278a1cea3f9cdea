// The deadlines' inputs read from the autopilot's parameters (autopilot_params.h).
#include <gtest/gtest.h>

#include "mavlink/enums.h"
#include "mavlink_adapter/autopilot_params.h"

namespace eamos::mavlink_adapter {
namespace {

// PX4 SIH took 9.7 s for a 4 m takeoff at MPC_TKO_SPEED 1.5 m/s: 1 s of spool-up and a 3 s
// climb-rate ramp come first. A deadline from the climb alone (14 s) left too little margin.
TEST(AutopilotParams, TakeoffDelaysAddUpFromSpoolUpAndRamp) {
  const Autopilot& px4 = *autopilot_for(mavlink::autopilot::PX4);
  FlightLimits l = combine_limits(px4, fleet::Limits{},
                                  {{"MPC_TKO_SPEED", 1.5f}, {"COM_SPOOLUP_TIME", 1.0f}, {"MPC_TKO_RAMP_T", 3.0f}});
  EXPECT_DOUBLE_EQ(l.takeoff_delay_s, 4.0);
  EXPECT_DOUBLE_EQ(l.motion.max_climb_mps, 1.5);
  EXPECT_NE(l.summary.find("MPC_TKO_RAMP_T 3 s"), std::string::npos) << l.summary;
}

TEST(AutopilotParams, AMissingOrZeroDelayIsNoDelayAndNoWarning) {
  const Autopilot& ap = *autopilot_for(mavlink::autopilot::ARDUPILOTMEGA);
  FlightLimits l = combine_limits(ap, fleet::Limits{},
                                  {{"WPNAV_SPEED", 1000}, {"WPNAV_SPEED_UP", 300}, {"WPNAV_SPEED_DN", 200},
                                   {"LAND_SPEED", 50}, {"MOT_SPOOL_TIME", 0.5f}});
  EXPECT_DOUBLE_EQ(l.takeoff_delay_s, 0.5);
  for (const std::string& w : l.warnings) EXPECT_EQ(w.find("SLEW"), std::string::npos) << w;
}

// The orbit's speed keeps its centripetal acceleration below the autopilot's: beyond
// WPNAV_ACCEL / MPC_ACC_HOR the vehicle cannot turn as tight and swings wide.
TEST(AutopilotParams, TheHorizontalAccelerationIsTheSlowerOfTheFleetsAndTheAutopilots) {
  const Autopilot& ap = *autopilot_for(mavlink::autopilot::ARDUPILOTMEGA);
  EXPECT_DOUBLE_EQ(combine_limits(ap, fleet::Limits{}, {{"WPNAV_ACCEL", 250}}).motion.max_accel_mps2, 2.5);
  const Autopilot& px4 = *autopilot_for(mavlink::autopilot::PX4);
  fleet::Limits gentle;
  gentle.max_accel_mps2 = 2.0;
  EXPECT_DOUBLE_EQ(combine_limits(px4, gentle, {{"MPC_ACC_HOR", 3}}).motion.max_accel_mps2, 2.0);
  FlightLimits told = combine_limits(px4, fleet::Limits{}, {{"MPC_ACC_HOR", 3}});
  EXPECT_DOUBLE_EQ(told.motion.max_accel_mps2, 3.0);
  EXPECT_NE(told.summary.find("MPC_ACC_HOR 3 m/s²"), std::string::npos) << told.summary;
}

// ArduCopter's stock RTL from relay's carrier, 5 m up and 30 m out: it climbs to RTL_ALT
// 15 m (2.5 m/s), flies home at WPNAV_SPEED 10 m/s, loiters RTL_LOIT_TIME 5 s, and lands
// from 15 m at LAND_SPEED 0.5 m/s. The straight way home and down counted 13 s of it.
TEST(AutopilotParams, ArduCopterReturnHomeCountsTheClimbToRtlAltAndTheLoiter) {
  const Autopilot& ap = *autopilot_for(mavlink::autopilot::ARDUPILOTMEGA);
  FlightLimits l = combine_limits(ap, fleet::Limits{},
                                  {{"WPNAV_SPEED", 1000}, {"WPNAV_SPEED_UP", 250}, {"WPNAV_SPEED_DN", 150},
                                   {"LAND_SPEED", 50}, {"LAND_SPEED_HIGH", 0}, {"RTL_ALT", 1500},
                                   {"RTL_CLIMB_MIN", 0}, {"RTL_SPEED", 0}, {"RTL_LOIT_TIME", 5000},
                                   {"RTL_ALT_FINAL", 0}});
  EXPECT_DOUBLE_EQ(l.rtl.altitude_m, 15.0);
  EXPECT_DOUBLE_EQ(l.rtl.wait_s, 5.0);
  EXPECT_TRUE(l.rtl.lands);
  EXPECT_DOUBLE_EQ(return_home_duration_s(l, 5, 30), 10 / 2.5 + 30 / 10.0 + 5 + 15 / 0.5);
  // Above RTL_ALT it returns at its altitude, plus RTL_CLIMB_MIN; RTL_SPEED slows the way home.
  l = combine_limits(ap, fleet::Limits{},
                     {{"WPNAV_SPEED", 1000}, {"WPNAV_SPEED_UP", 250}, {"LAND_SPEED", 50}, {"RTL_ALT", 1500},
                      {"RTL_CLIMB_MIN", 200}, {"RTL_SPEED", 500}, {"RTL_LOIT_TIME", 0}, {"RTL_ALT_FINAL", 0}});
  EXPECT_DOUBLE_EQ(return_home_duration_s(l, 20, 30), 2 / 2.5 + 30 / 5.0 + 22 / 0.5);
}

// PX4's stock return climbs to RTL_RETURN_ALT 60 m before it flies home.
TEST(AutopilotParams, Px4ReturnHomeCountsTheClimbToRtlReturnAltAndTheLandDelay) {
  const Autopilot& px4 = *autopilot_for(mavlink::autopilot::PX4);
  FlightLimits l = combine_limits(px4, fleet::Limits{},
                                  {{"MPC_XY_CRUISE", 5}, {"MPC_Z_VEL_MAX_UP", 3}, {"MPC_TKO_SPEED", 1.5f},
                                   {"MPC_Z_VEL_MAX_DN", 1}, {"MPC_LAND_SPEED", 0.7f}, {"RTL_RETURN_ALT", 60},
                                   {"RTL_LAND_DELAY", 2}});
  EXPECT_NEAR(return_home_duration_s(l, 5, 30), 55 / 1.5 + 30 / 5.0 + 2 + 60 / 0.7, 1e-4);
}

// A return that does not land never ends a ReturnHome (it waits for on-ground): said at start.
TEST(AutopilotParams, AReturnThatDoesNotLandIsAWarning) {
  const Autopilot& ap = *autopilot_for(mavlink::autopilot::ARDUPILOTMEGA);
  FlightLimits l = combine_limits(ap, fleet::Limits{}, {{"RTL_ALT", 1500}, {"RTL_ALT_FINAL", 500}});
  EXPECT_FALSE(l.rtl.lands);
  bool warned = false;
  for (const std::string& w : l.warnings) warned = warned || w.find("RTL_ALT_FINAL > 0") != std::string::npos;
  EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace eamos::mavlink_adapter
