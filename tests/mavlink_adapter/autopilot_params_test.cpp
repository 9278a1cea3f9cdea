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

}  // namespace
}  // namespace eamos::mavlink_adapter
