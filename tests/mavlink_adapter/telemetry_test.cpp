// The autopilot's NED frame and the mission frame, and what telemetry frames change.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "mavlink/enums.h"
#include "mavlink/payloads.h"
#include "mavlink_adapter/autopilot.h"
#include "mavlink_adapter/telemetry.h"

namespace eamos::mavlink_adapter {
namespace {

namespace ml = eamos::mavlink;

TEST(FrameMapping, NorthEastDownBecomesEastNorthUpAroundHome) {
  fleet::Vec3 home{10, 20, 1};
  fleet::Vec3 p = ned_to_mission({3, 4, -5}, home);  // 3 m north, 4 m east, 5 m up
  EXPECT_DOUBLE_EQ(p.x, 14);
  EXPECT_DOUBLE_EQ(p.y, 23);
  EXPECT_DOUBLE_EQ(p.z, 6);
  fleet::Vec3 back = mission_to_ned(p, home);
  EXPECT_DOUBLE_EQ(back.x, 3);
  EXPECT_DOUBLE_EQ(back.y, 4);
  EXPECT_DOUBLE_EQ(back.z, -5);
}

ml::Frame frame(ml::Message m) {
  ml::Frame f;
  f.message = std::move(m);
  return f;
}

TEST(Telemetry, HeartbeatCarriesArmedAndModeAndLandedFollowsExtendedSysState) {
  VehicleState v;
  EXPECT_TRUE(v.landed());
  ml::Heartbeat hb;
  hb.autopilot = ml::autopilot::PX4;
  hb.base_mode = ml::mode_flag::SAFETY_ARMED;
  hb.custom_mode = px4::OFFBOARD;
  Changes c = apply_telemetry(v, frame(ml::pack(hb)));
  EXPECT_TRUE(c.heartbeat && c.armed);
  EXPECT_TRUE(v.armed);
  EXPECT_EQ(v.custom_mode, px4::OFFBOARD);
  EXPECT_TRUE(v.landed());  // armed, but nothing says it left the ground
  apply_telemetry(v, frame(ml::pack(ml::ExtendedSysState{0, ml::landed::ON_GROUND})));
  c = apply_telemetry(v, frame(ml::pack(ml::ExtendedSysState{0, ml::landed::IN_AIR})));
  EXPECT_TRUE(c.landed);
  EXPECT_FALSE(v.landed());
}

TEST(Telemetry, UnknownBatteryKeepsTheLastKnownCharge) {
  VehicleState v;
  ml::SysStatus s;
  s.battery_remaining = 80;
  apply_telemetry(v, frame(ml::pack(s)));
  s.battery_remaining = -1;
  apply_telemetry(v, frame(ml::pack(s)));
  EXPECT_DOUBLE_EQ(v.battery, 80);
}

TEST(Telemetry, RefusesAPositionWithNaNOrInfinityOrBeyondAnyVehicle) {
  VehicleState v;
  ml::LocalPositionNed p;
  p.x = 3;
  ASSERT_FALSE(apply_telemetry(v, frame(ml::pack(p))).rejected);
  for (float bad : {std::nanf(""), std::numeric_limits<float>::infinity(), 5e6f}) {
    ml::LocalPositionNed q = p;
    q.z = bad;
    Changes c = apply_telemetry(v, frame(ml::pack(q)));
    ASSERT_TRUE(c.rejected) << bad;
    EXPECT_STREQ(c.rejected, "LOCAL_POSITION_NED with NaN, an infinity or a value out of range");
    EXPECT_FALSE(c.position);
    EXPECT_EQ(v.ned.z, 0);  // the last good position stays
  }
  ml::LocalPositionNed fast = p;
  fast.vx = std::nanf("");
  EXPECT_TRUE(apply_telemetry(v, frame(ml::pack(fast))).rejected);
  EXPECT_EQ(v.ned.x, 3);
}

TEST(Telemetry, RefusesUnknownLandedStatesAndBatteriesBeyondAHundredPercent) {
  VehicleState v;
  apply_telemetry(v, frame(ml::pack(ml::ExtendedSysState{0, ml::landed::IN_AIR})));
  Changes c = apply_telemetry(v, frame(ml::pack(ml::ExtendedSysState{0, 77})));
  EXPECT_STREQ(c.rejected, "EXTENDED_SYS_STATE with an unknown landed state");
  EXPECT_EQ(v.landed_state, ml::landed::IN_AIR);
  ml::SysStatus s;
  s.battery_remaining = 120;
  EXPECT_STREQ(apply_telemetry(v, frame(ml::pack(s))).rejected, "SYS_STATUS with a battery beyond 0 to 100 %");
  EXPECT_DOUBLE_EQ(v.battery, -1);
  ml::GlobalPositionInt g;
  g.alt = 2'000'000'000;
  EXPECT_STREQ(apply_telemetry(v, frame(ml::pack(g))).rejected, "GLOBAL_POSITION_INT with an altitude beyond 100 km");
  EXPECT_FALSE(v.have_altitude);
}

TEST(Autopilots, Px4AndArduPilotSelectTheirSetpointModes) {
  const Autopilot* p = autopilot_for(ml::autopilot::PX4);
  const Autopilot* a = autopilot_for(ml::autopilot::ARDUPILOTMEGA);
  ASSERT_TRUE(p && a);
  EXPECT_EQ(set_mode_params(*p, p->setpoint_mode), (std::array<float, 3>{1, 6, 0}));
  EXPECT_EQ(set_mode_params(*a, a->setpoint_mode), (std::array<float, 3>{1, 4, 0}));
  EXPECT_EQ(mode_name(*p, px4::LOITER), "AUTO.LOITER");
  EXPECT_EQ(mode_name(*a, 4), "GUIDED");
  EXPECT_EQ(autopilot_for(ml::autopilot::GENERIC), nullptr);
}

}  // namespace
}  // namespace eamos::mavlink_adapter
