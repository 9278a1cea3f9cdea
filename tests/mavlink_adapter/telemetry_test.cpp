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

// After an accepted ARM the first HEARTBEAT that still says disarmed may have been made
// before the command took effect: not believed. The next one is.
TEST(Telemetry, TheFirstHeartbeatContradictingAnAcceptedArmIsNotBelievedTheNextIs) {
  VehicleState v;
  v.armed_by_command(true);  // as the adapter sets it on the ACK
  ml::Heartbeat disarmed;
  disarmed.autopilot = ml::autopilot::PX4;
  Changes c = apply_telemetry(v, frame(ml::pack(disarmed)));
  EXPECT_TRUE(c.heartbeat && c.armed_unconfirmed);
  EXPECT_FALSE(c.armed);
  EXPECT_TRUE(v.armed);
  c = apply_telemetry(v, frame(ml::pack(disarmed)));  // the vehicle really is disarmed
  EXPECT_TRUE(c.armed && !c.armed_unconfirmed);
  EXPECT_FALSE(v.armed);

  // A HEARTBEAT that confirms the ACK ends the doubt: a disarm after it is believed at once.
  ml::Heartbeat armed = disarmed;
  armed.base_mode = ml::mode_flag::SAFETY_ARMED;
  v.armed_by_command(true);
  c = apply_telemetry(v, frame(ml::pack(armed)));
  EXPECT_FALSE(c.armed || c.armed_unconfirmed);
  c = apply_telemetry(v, frame(ml::pack(disarmed)));
  EXPECT_TRUE(c.armed);
  EXPECT_FALSE(v.armed);
}

ml::LocalPositionNed at(uint32_t ms, float north, float vx) {
  ml::LocalPositionNed p;
  p.time_boot_ms = ms;
  p.x = north;
  p.z = -3;
  p.vx = vx;
  return p;
}

// PX4 SIH once held 0.3-0.6 m short of its setpoint for seconds while its estimator said it
// moved towards it at 0.5 m/s: standing still is judged on where the position goes.
TEST(Telemetry, SettlingSpeedIsThePositionsOwnOverHalfASecondOfTheVehiclesTime) {
  VehicleState v;
  apply_telemetry(v, frame(ml::pack(at(1000, 4.0f, 0.5f))));
  EXPECT_DOUBLE_EQ(v.settling_speed(), 0.5);  // one report: the estimator's word only
  apply_telemetry(v, frame(ml::pack(at(1200, 4.0f, 0.5f))));
  EXPECT_DOUBLE_EQ(v.settling_speed(), 0.5);  // 200 ms: still too short a track
  for (uint32_t ms = 1300; ms <= 2000; ms += 100) apply_telemetry(v, frame(ml::pack(at(ms, 4.0f, 0.5f))));
  EXPECT_DOUBLE_EQ(v.settling_speed(), 0.0);  // it said 0.5 m/s, and stood
  EXPECT_EQ(v.track.front().first, 1500u);    // only the last half second is kept
  // Moving 1 m/s by its position, whatever it says of its velocity.
  for (uint32_t ms = 2100; ms <= 2500; ms += 100)
    apply_telemetry(v, frame(ml::pack(at(ms, 4.0f + (ms - 2000) / 1000.0f, 0.0f))));
  EXPECT_NEAR(v.settling_speed(), 1.0, 1e-5);
  // A reboot (time going back) starts the track anew.
  apply_telemetry(v, frame(ml::pack(at(50, 0.0f, 0.2f))));
  EXPECT_EQ(v.track.size(), 1u);
  EXPECT_FLOAT_EQ(v.settling_speed(), 0.2f);
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

// The orbit's radius is measured from the centre the autopilot reports (orbit_flight.cpp):
// a centre off the earth, a NaN radius or a position off the earth is refused whole.
TEST(Telemetry, TakesTheOrbitCentreInAGlobalFrameAndRefusesOneOffTheEarth) {
  VehicleState v;
  ml::OrbitExecutionStatus o;
  o.frame = 0;  // MAV_FRAME_GLOBAL
  o.radius = -5;
  o.x = 473'977'420, o.y = 85'455'940;
  ASSERT_FALSE(apply_telemetry(v, frame(ml::pack(o))).rejected);
  EXPECT_TRUE(v.have_orbit_centre);
  EXPECT_EQ(v.orbit_centre_lat_e7, 473'977'420);
  EXPECT_EQ(v.orbit_centre_lon_e7, 85'455'940);
  ml::OrbitExecutionStatus off = o;
  off.x = 950'000'000;  // 95° north
  EXPECT_STREQ(apply_telemetry(v, frame(ml::pack(off))).rejected,
               "ORBIT_EXECUTION_STATUS with NaN, a radius out of range or a centre off the earth");
  off = o;
  off.radius = std::nanf("");
  EXPECT_TRUE(apply_telemetry(v, frame(ml::pack(off))).rejected);
  EXPECT_EQ(v.orbit_centre_lat_e7, 473'977'420);  // the last good centre stays
  // A centre in a local frame (m * 1e4 from an origin the adapter does not know) is not used.
  VehicleState local;
  ml::OrbitExecutionStatus l = o;
  l.frame = ml::kFrameLocalNed;
  EXPECT_FALSE(apply_telemetry(local, frame(ml::pack(l))).rejected);
  EXPECT_FALSE(local.have_orbit_centre);
  ml::GlobalPositionInt g;
  g.lon = -1'900'000'000;
  EXPECT_STREQ(apply_telemetry(v, frame(ml::pack(g))).rejected,
               "GLOBAL_POSITION_INT with a latitude or longitude off the earth");
}

TEST(FrameMapping, MetresBetweenTwoPositionsAndBackAgree) {
  const int32_t lat = 473'977'420, lon = 85'455'940;  // PX4 SITL's home
  auto [lat2, lon2] = offset_lat_lon(lat, lon, 3.0, -4.0);
  fleet::Vec3 d = north_east_between(lat, lon, lat2, lon2);
  EXPECT_NEAR(d.x, 3.0, 0.01);  // degE7 is 1.1 cm
  EXPECT_NEAR(d.y, -4.0, 0.01);
  // One degree of latitude is 111.2 km on PX4's earth (radius 6371 km).
  EXPECT_NEAR(north_east_between(lat, lon, lat + 10'000'000, lon).x, 111'195.0, 1.0);
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
