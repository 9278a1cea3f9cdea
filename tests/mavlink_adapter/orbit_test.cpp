// Orbit over MAVLink: PX4 flies it itself after MAV_CMD_DO_ORBIT, ArduPilot Copter (no
// DO_ORBIT) from the adapter's setpoints; either way it circles where it started until
// cancelled or preempted, like the simulator. Against the simulated vehicle over loopback UDP.
#include <gtest/gtest.h>

#include <cmath>

#include "flight.h"
#include "mavlink/enums.h"
#include "mavlink/link.h"
#include "mavlink/payloads.h"

namespace eamos::mavlink_adapter {
namespace {

namespace ml = eamos::mavlink;
using sim_vehicle::Mode;
using test::Flight;
using test::kSpeed;
using test::VehicleThread;

constexpr double kRadius = 3.0;

struct Orbiting {
  std::optional<mid::ActionEnd> end;
  mid::ActionId id = mid::kNoAction;
};

/// Arms, takes off to 3 m over home (the origin) and starts Orbit(3) there; runs `run_s`.
void take_off_and_orbit(Flight& f, Orbiting& o, double run_s, double radius = kRadius) {
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  ASSERT_EQ(f.fly("Takeoff", {3}).outcome, mid::Outcome::succeeded);
  o.id = f.drone->start({"Orbit", {radius}}, [&o](const mid::ActionEnd& e) { o.end = e; });
  f.loop.run_until(f.loop.now() + run_s);
}

double bearing(const mid::DroneState& s) { return std::atan2(s.y, s.x); }

/// How far counter-clockwise `to` lies from `from`, in (-pi, pi].
double turned(double from, double to) { return std::remainder(to - from, 2.0 * M_PI); }

Mode vehicle_mode(VehicleThread& v) {
  return v.inspect([](const sim_vehicle::SimVehicle& s) { return s.mode(); });
}
int do_orbits(VehicleThread& v) {
  return v.inspect([](const sim_vehicle::SimVehicle& s) { return s.received(ml::cmd::DO_ORBIT); });
}

TEST(MavlinkOrbit, Px4FliesOrbitItselfAfterDoOrbitCirclingTheStartCounterClockwise) {
  VehicleThread vehicle(25360, 1, kSpeed);
  Flight f(25360);
  Orbiting o;
  take_off_and_orbit(f, o, 8.0);
  EXPECT_FALSE(o.end);  // an orbit has no end of its own
  EXPECT_EQ(do_orbits(vehicle), 1);
  EXPECT_EQ(vehicle_mode(vehicle), Mode::orbit);
  for (int i = 0; i < 3; ++i) {
    mid::DroneState before = f.drone->state();
    f.loop.run_until(f.loop.now() + 0.5);
    mid::DroneState after = f.drone->state();
    EXPECT_NEAR(std::hypot(after.x, after.y), kRadius, 0.5);  // on the circle around the start
    EXPECT_NEAR(after.z, 3.0, 0.3);
    EXPECT_GT(turned(bearing(before), bearing(after)), 0.2);  // going round, counter-clockwise
  }
}

TEST(MavlinkOrbit, CancellingAPx4OrbitLeavesOrbitModeAndHoldsWithSetpoints) {
  VehicleThread vehicle(25361, 1, kSpeed);
  Flight f(25361);
  Orbiting o;
  take_off_and_orbit(f, o, 8.0);
  ASSERT_EQ(vehicle_mode(vehicle), Mode::orbit);
  EXPECT_TRUE(f.drone->cancel(o.id));
  f.loop.run_until(f.loop.now() + 3.0);
  ASSERT_TRUE(o.end);
  EXPECT_EQ(o.end->outcome, mid::Outcome::cancelled);
  EXPECT_EQ(vehicle_mode(vehicle), Mode::setpoint);  // OFFBOARD again, our stream in control
  mid::DroneState held = f.drone->state();
  f.loop.run_until(f.loop.now() + 2.0);
  mid::DroneState later = f.drone->state();
  EXPECT_NEAR(later.x, held.x, 0.3);  // stopped circling
  EXPECT_NEAR(later.y, held.y, 0.3);
}

TEST(MavlinkOrbit, AFlyToPreemptingAPx4OrbitLeavesOrbitAndArrives) {
  VehicleThread vehicle(25362, 1, kSpeed);
  Flight f(25362);
  Orbiting o;
  take_off_and_orbit(f, o, 6.0);
  mid::ActionEnd e = f.fly("FlyTo", {8, 4, 4});
  ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
  ASSERT_TRUE(o.end);
  EXPECT_EQ(o.end->outcome, mid::Outcome::preempted);
  EXPECT_NEAR(f.drone->state().x, 8.0, 0.5);
  EXPECT_NEAR(f.drone->state().y, 4.0, 0.5);
  EXPECT_EQ(vehicle_mode(vehicle), Mode::setpoint);
}

TEST(MavlinkOrbit, ArduPilotOrbitIsStillFlownFromSetpointsInGuided) {
  VehicleThread vehicle(25363, 1, kSpeed, sim_vehicle::ardupilot_dialect());
  Flight f(25363);
  Orbiting o;
  take_off_and_orbit(f, o, 8.0);
  EXPECT_FALSE(o.end);
  EXPECT_EQ(do_orbits(vehicle), 0);
  EXPECT_EQ(vehicle_mode(vehicle), Mode::setpoint);
  mid::DroneState before = f.drone->state();
  f.loop.run_until(f.loop.now() + 0.5);
  mid::DroneState after = f.drone->state();
  EXPECT_NEAR(std::hypot(after.x, after.y), kRadius, 1.0);
  EXPECT_GT(turned(bearing(before), bearing(after)), 0.2);
}

TEST(MavlinkOrbit, DoOrbitRefusedByPx4FailsWithTheResultInWordsAndKeepsHolding) {
  VehicleThread vehicle(25364, 1, kSpeed);
  Flight f(25364);
  Orbiting o;
  take_off_and_orbit(f, o, 4.0, 2000.0);  // beyond PX4's largest orbit (MC_ORBIT_RAD_MAX)
  ASSERT_TRUE(o.end);
  EXPECT_EQ(o.end->outcome, mid::Outcome::failed);
  EXPECT_EQ(o.end->reason,
            "refused by PX4: MAV_CMD_DO_ORBIT: MAV_RESULT_DENIED (denied by the autopilot)");
  EXPECT_EQ(vehicle_mode(vehicle), Mode::setpoint);
  EXPECT_NEAR(std::hypot(f.drone->state().x, f.drone->state().y), 0.0, 0.5);
}

TEST(MavlinkOrbit, APilotsModeSwitchFailsAPx4Orbit) {
  VehicleThread vehicle(25365, 1, kSpeed);
  Flight f(25365);
  Orbiting o;
  take_off_and_orbit(f, o, 4.0);
  ASSERT_FALSE(o.end);
  // A ground station on the same vehicle switches to POSCTL, as a pilot's switch would.
  auto gcs = ml::Link::open(*ml::parse_url("udpout://127.0.0.1:" + std::to_string(vehicle.port())).endpoint,
                            [](ml::Frame) {});
  ASSERT_TRUE(gcs.link) << gcs.error;
  ml::CommandLong c;
  c.target_system = 1;
  c.target_component = 1;
  c.command = ml::cmd::DO_SET_MODE;
  c.param = {1, ml::px4::MAIN_POSCTL, 0};
  gcs.link->send(ml::Encoder{1, 190, 0}.encode(ml::pack(c)));
  f.loop.run_until(f.loop.now() + 4.0);
  ASSERT_TRUE(o.end);
  EXPECT_EQ(o.end->outcome, mid::Outcome::failed);
  EXPECT_EQ(o.end->reason, "the vehicle left ORBIT for POSCTL");
  EXPECT_EQ(vehicle_mode(vehicle), Mode::manual);  // and the adapter does not switch back
}

}  // namespace
}  // namespace eamos::mavlink_adapter
