// The mavlink adapter against the simulated PX4-like vehicle over loopback UDP, both on real
// time sped up 4×: every test flies a few mission seconds. Each test has its own port.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>

#include "mavlink/enums.h"
#include "mavlink/link.h"
#include "mavlink/payloads.h"
#include "flight.h"

namespace eamos::mavlink_adapter {
namespace {

using test::Flight;
using test::kSpeed;

// A second ground station on the same vehicle (its own address), as a pilot's or a
// stranger's would be.
mavlink::OpenResult ground_station_on(int port) {
  return mavlink::Link::open(*eamos::fleet::parse_link_url("udpout://127.0.0.1:" + std::to_string(port)).endpoint,
                             [](mavlink::Frame) {});
}

// DO_SET_MODE to POSCTL, what a pilot's mode switch sends.
mavlink::CommandLong posctl_for(uint8_t sysid) {
  mavlink::CommandLong c;
  c.target_system = sysid;
  c.target_component = 1;
  c.command = mavlink::cmd::DO_SET_MODE;
  c.param = {1, mavlink::px4::MAIN_POSCTL, 0};
  return c;
}

TEST(MavlinkFlight, ConnectsAndRecognisesPx4) {
  test::VehicleThread vehicle(25311, 1, kSpeed);
  Flight f(25311);
  ASSERT_EQ(f.created.status, mid::CreateStatus::success) << f.created.message;
  auto* d = dynamic_cast<MavlinkDrone*>(f.drone.get());
  ASSERT_NE(d->autopilot(), nullptr);
  EXPECT_STREQ(d->autopilot()->name, "PX4");
}

TEST(MavlinkFlight, ArmTakeoffFlyAndLand) {
  test::VehicleThread vehicle(25312, 1, kSpeed);
  Flight f(25312);
  ASSERT_TRUE(f.drone) << f.created.message;
  mid::ActionEnd e = f.fly("Arm");
  ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
  EXPECT_TRUE(f.drone->state().armed);

  e = f.fly("Takeoff", {3});
  ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
  EXPECT_NEAR(f.drone->state().z, 3.0, 0.3);
  EXPECT_FALSE(f.drone->state().landed);

  e = f.fly("FlyByX", {5});
  ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
  EXPECT_NEAR(f.drone->state().x, 5.0, 0.5);
  EXPECT_NEAR(f.drone->state().z, 3.0, 0.3);

  e = f.fly("Takeoff", {5});  // in the air: climbs to the altitude, as in the simulator
  ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
  EXPECT_NEAR(f.drone->state().z, 5.0, 0.3);

  e = f.fly("Land");
  ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
  EXPECT_TRUE(f.drone->state().landed);
  EXPECT_NEAR(f.drone->state().z, 0.0, 0.1);
}

// PX4 takes off to an altitude above mean sea level. Its home (relative_alt's reference) is
// where it stood when it armed, which its EKF no longer puts at the ground's altitude some
// seconds later (SITL: 0.2-0.3 m, a Takeoff(3) after the auto-disarm's re-arm hovered at
// 2.7 m, the edge of the 0.3 m band, and timed out): the altitude is asked for from where
// the vehicle is now, in the frame the goal is judged in.
TEST(MavlinkFlight, Px4TakesOffToTheAltitudeAboveTheGroundWhenItsHomeIsNotWhereItStands) {
  sim_vehicle::VehicleOptions o;
  o.home_above_origin_m = -0.5;
  test::VehicleThread vehicle(25379, kSpeed, o);
  Flight f(25379);
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  mid::ActionEnd e = f.fly("Takeoff", {3});
  ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
  EXPECT_NEAR(vehicle.inspect([](const sim_vehicle::SimVehicle& v) { return v.drone().state().z; }), 3.0, 0.3);
}

// A Takeoff asks for a height. PX4 SITL's own hover after its takeoff wandered up to 1 m from
// where it took off: the Takeoff is done at its height all the same, and the hold that follows
// brings the vehicle back over where it took off.
TEST(MavlinkFlight, ATakeoffIsDoneAtItsHeightWhereverTheHoverWandersAndTheHoldBringsItBack) {
  sim_vehicle::VehicleOptions o;
  o.hover_wander_east_m = 1.0;
  test::VehicleThread vehicle(25384, kSpeed, o);
  Flight f(25384);
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  auto here = [&] { return vehicle.inspect([](const sim_vehicle::SimVehicle& v) { return v.drone().state(); }); };
  const double start_x = here().x;
  double farthest = 0.0;
  mid::ActionEnd e = f.fly("Takeoff", {3}, 8.0);
  ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
  EXPECT_NEAR(here().z, 3.0, 0.3);
  for (int i = 0; i < 60; ++i) {  // 3 mission s of the hold
    farthest = std::max(farthest, std::fabs(here().x - start_x));
    f.loop.run_until(f.loop.now() + 0.05);
  }
  EXPECT_GT(farthest, 0.5) << "the vehicle's hover never wandered: the test tests nothing";
  EXPECT_NEAR(here().x, start_x, 0.1);
}

TEST(MavlinkFlight, ArduPilotTakesOffInGuidedToAnAltitudeAboveHome) {
  test::VehicleThread vehicle(25318, 1, kSpeed, sim_vehicle::ardupilot_dialect());
  Flight f(25318);
  ASSERT_TRUE(f.drone) << f.created.message;
  EXPECT_STREQ(dynamic_cast<MavlinkDrone*>(f.drone.get())->autopilot()->name, "ArduPilot");
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  mid::ActionEnd e = f.fly("Takeoff", {4});
  ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
  EXPECT_NEAR(f.drone->state().z, 4.0, 0.3);
  e = f.fly("FlyTo", {-3, 2, 5});
  ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
  EXPECT_NEAR(f.drone->state().x, -3.0, 0.5);
  EXPECT_NEAR(f.drone->state().y, 2.0, 0.5);
  e = f.fly("ReturnHome");
  ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
  EXPECT_TRUE(f.drone->state().landed);
  EXPECT_NEAR(f.drone->state().x, 0.0, 0.5);
}

// PX4 reports its orbit (ORBIT_EXECUTION_STATUS) while it flies DO_ORBIT; ArduCopter has no
// such stream and answers the rate with a STATUSTEXT each time: it is not asked.
TEST(MavlinkFlight, TheOrbitStatusIsAskedForOnlyFromAnAutopilotThatFliesDoOrbit) {
  for (const sim_vehicle::Dialect* d : {&sim_vehicle::px4_dialect(), &sim_vehicle::ardupilot_dialect()}) {
    SCOPED_TRACE(d->name);
    int port = d == &sim_vehicle::px4_dialect() ? 25409 : 25410;
    test::VehicleThread vehicle(port, 1, kSpeed, *d);
    Flight f(port);
    ASSERT_TRUE(f.drone) << f.created.message;
    auto asked = [&](uint32_t id) {
      return vehicle.inspect([id](sim_vehicle::SimVehicle& v) { return v.intervals_asked(id); });
    };
    // BATTERY_STATUS is the last rate the adapter asks for, one command after the other.
    double give_up = f.loop.now() + 5;
    while (asked(mavlink::msg::BATTERY_STATUS) == 0 && f.loop.now() < give_up) f.loop.run_until(f.loop.now() + 0.01);
    ASSERT_EQ(asked(mavlink::msg::BATTERY_STATUS), 1);
    EXPECT_EQ(asked(mavlink::msg::LOCAL_POSITION_NED), 1);
    EXPECT_EQ(asked(mavlink::msg::ORBIT_EXECUTION_STATUS), d->do_orbit ? 1 : 0);
  }
}

// A picture is taken when the vehicle says so, not when it accepts the command: each
// autopilot's own command (PX4 DO_DIGICAM_CONTROL, ArduPilot IMAGE_START_CAPTURE) and its
// camera's confirmation (CAMERA_TRIGGER, CAMERA_FEEDBACK) make one picture.
TEST(MavlinkFlight, TakePictureSucceedsOnceTheVehicleConfirmsItsPicture) {
  for (const sim_vehicle::Dialect* d : {&sim_vehicle::px4_dialect(), &sim_vehicle::ardupilot_dialect()}) {
    SCOPED_TRACE(d->name);
    int port = d == &sim_vehicle::px4_dialect() ? 25370 : 25371;
    test::VehicleThread vehicle(port, 1, kSpeed, *d);
    Flight f(port);
    ASSERT_TRUE(f.drone) << f.created.message;
    mid::ActionEnd e = f.fly("TakePicture");
    EXPECT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
    EXPECT_EQ(f.drone->state().pictures, 1);
    EXPECT_EQ(vehicle.inspect([&](sim_vehicle::SimVehicle& v) { return v.received(d->picture_command); }), 1);
  }
}

TEST(MavlinkFlight, TakePictureAcceptedButNeverConfirmedFailsSayingSo) {
  test::VehicleThread vehicle(25372, 1, kSpeed, sim_vehicle::ardupilot_dialect(), 100.0, /*camera_confirms=*/false);
  Flight f(25372);
  ASSERT_TRUE(f.drone) << f.created.message;
  mid::ActionEnd e = f.fly("TakePicture");
  EXPECT_EQ(e.outcome, mid::Outcome::failed);
  EXPECT_NE(e.reason.find("no picture: ArduPilot accepted MAV_CMD_IMAGE_START_CAPTURE but no camera confirmed"),
            std::string::npos)
      << e.reason;
  EXPECT_EQ(f.drone->state().pictures, 0);
}

// A vehicle whose clock runs at half of mission time (a SITL that cannot keep up with
// --speed on a loaded machine): the FlyTo of 300 m takes over 30 s of the vehicle's time,
// over 60 mission seconds, beyond its deadline from the limits (55 s); deadlines follow the
// vehicle's clock.
TEST(MavlinkFlight, DeadlinesFollowTheVehiclesClockWhenItRunsSlowerThanMissionTime) {
  test::VehicleThread vehicle(25373, 1, kSpeed / 2);
  Flight f(25373);
  ASSERT_TRUE(f.drone) << f.created.message;
  mid::ActionEnd armed = f.fly("Arm");
  ASSERT_EQ(armed.outcome, mid::Outcome::succeeded) << armed.reason;
  mid::ActionEnd up = f.fly("Takeoff", {3});
  ASSERT_EQ(up.outcome, mid::Outcome::succeeded) << up.reason;
  mid::ActionEnd e = f.fly("FlyTo", {300, 0, 3}, 150);
  EXPECT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
}

TEST(MavlinkFlight, ArmRefusedByTheAutopilotFailsWithItsResultInWords) {
  test::VehicleThread vehicle(25313, 1, kSpeed, sim_vehicle::px4_dialect(), 0.0);  // empty battery
  Flight f(25313);
  ASSERT_TRUE(f.drone) << f.created.message;
  mid::ActionEnd e = f.fly("Arm");
  EXPECT_EQ(e.outcome, mid::Outcome::failed);
  EXPECT_EQ(e.reason, "refused by PX4: MAV_CMD_COMPONENT_ARM_DISARM: MAV_RESULT_DENIED (denied by the autopilot)");
  EXPECT_EQ(e.failure, mid::FailureReason::refused);
  EXPECT_EQ(e.detail, "MAV_CMD_COMPONENT_ARM_DISARM: MAV_RESULT_DENIED (denied by the autopilot)");
  EXPECT_FALSE(f.drone->state().armed);
}

// An ARM lost on its way (no ACK) for an Arm that is cancelled meanwhile (the mission was
// abandoned) is not sent again after the ACK timeout: the resend would arm a vehicle the
// mission had left on the ground, disarmed, with no failsafe to come for it.
TEST(MavlinkFlight, AnArmWhoseActionEndedIsNotSentAgain) {
  sim_vehicle::VehicleOptions o = test::VehicleThread::options(sim_vehicle::px4_dialect(), 1, 100.0, true);
  o.arms_lost = 1;
  test::VehicleThread vehicle(25324, kSpeed, o);
  Flight f(25324);
  ASSERT_TRUE(f.drone) << f.created.message;
  auto arms = [&] {
    return vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.received(mavlink::cmd::COMPONENT_ARM_DISARM); });
  };
  std::optional<mid::ActionEnd> end;
  mid::ActionId id = f.drone->start({"Arm", {}}, [&](const mid::ActionEnd& e) { end = e; });
  // The Arm may switch the mode first: wait for its ARM to reach the vehicle.
  for (double until = f.loop.now() + 5.0; arms() == 0 && f.loop.now() < until;)
    f.loop.run_until(f.loop.now() + 0.05);
  ASSERT_EQ(arms(), 1);
  ASSERT_FALSE(end);
  EXPECT_TRUE(f.drone->cancel(id));
  f.loop.run_until(f.loop.now() + 5.0);  // past the ARM's ACK timeout (1 s) and its three resends
  EXPECT_EQ(arms(), 1) << "the ARM was sent again after its Arm ended";
  EXPECT_FALSE(vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.drone().state().armed; }));
  EXPECT_FALSE(f.drone->state().armed);
  ASSERT_TRUE(end);
  EXPECT_EQ(end->outcome, mid::Outcome::cancelled);
}

// A HEARTBEAT made before the ARM took effect, arriving after its ACK (MAVLink orders
// nothing between the two): believed, it would show the drone disarmed on the ground during
// its Takeoff, which the adapter takes for the auto-disarm and answers with a second ARM and a
// repeated takeoff (and a real auto-disarm after it would then fail the Takeoff). The same
// after the DISARM: a stale armed HEARTBEAT would show a drone the mission disarmed armed.
TEST(MavlinkFlight, AHeartbeatMadeBeforeTheArmOrDisarmTookEffectIsNotBelieved) {
  sim_vehicle::VehicleOptions o = test::VehicleThread::options(sim_vehicle::px4_dialect(), 1, 100.0, true);
  o.stale_heartbeats_after_arming = 1;
  test::VehicleThread vehicle(25326, kSpeed, o);
  Flight f(25326);
  ASSERT_TRUE(f.drone) << f.created.message;
  std::string said;
  f.drone->set_message_sink([&](const std::string& text) { said += text + "\n"; });
  int disarmed_states = 0;  // published states saying disarmed between the Arm and the Land
  bool watching = false;
  mid::SubscriptionId sub =
      f.drone->subscribe([&](const mid::DroneState& s) { disarmed_states += watching && !s.armed; });
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded) << said;
  watching = true;
  mid::ActionEnd up = f.fly("Takeoff", {3});
  ASSERT_EQ(up.outcome, mid::Outcome::succeeded) << up.reason << "\n" << said;
  ASSERT_EQ(f.fly("Land").outcome, mid::Outcome::succeeded) << said;
  watching = false;
  EXPECT_EQ(disarmed_states, 0) << said;
  EXPECT_EQ(said.find("disarmed the vehicle"), std::string::npos) << said;  // the auto-disarm notes
  EXPECT_NE(said.find("after the autopilot accepted the ARM still said disarmed"), std::string::npos) << said;
  EXPECT_EQ(vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.received(mavlink::cmd::COMPONENT_ARM_DISARM); }),
            1);

  ASSERT_EQ(f.fly("Disarm").outcome, mid::Outcome::succeeded) << said;
  f.drone->unsubscribe(sub);
  int armed_states = 0;
  f.drone->subscribe([&](const mid::DroneState& s) { armed_states += s.armed; });
  f.loop.run_until(f.loop.now() + 1.0);  // every HEARTBEAT the vehicle sends after its ACK
  EXPECT_EQ(armed_states, 0) << said;
  EXPECT_FALSE(f.drone->state().armed);
  EXPECT_NE(said.find("after the autopilot accepted the DISARM still said armed"), std::string::npos) << said;
}

// PX4 SITL stood disarmed in OFFBOARD after a mission that ended with its NAV_LAND, and
// refuses to arm there without setpoints ("Arming denied: Resolve system health failures
// first"). A DEX arms only after its wait for the vehicle's fix, when the vehicle's mode is
// known: the Arm must switch to AUTO.LOITER first, as it does when the mode is unknown.
TEST(MavlinkFlight, APx4LeftInOffboardByTheLastMissionSwitchesToHoldBeforeItArms) {
  sim_vehicle::VehicleOptions o;
  o.boot_mode = sim_vehicle::Mode::setpoint;
  test::VehicleThread vehicle(25387, kSpeed, o);
  Flight f(25387);
  ASSERT_TRUE(f.drone) << f.created.message;
  for (double until = f.loop.now() + 5.0; f.drone->state().mode.empty() && f.loop.now() < until;)
    f.loop.run_until(f.loop.now() + 0.05);
  ASSERT_EQ(f.drone->state().mode, "OFFBOARD");
  mid::ActionEnd e = f.fly("Arm");
  ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
  EXPECT_EQ(vehicle.inspect([](const sim_vehicle::SimVehicle& v) { return v.mode(); }), sim_vehicle::Mode::hold);
}

// The adapter is an onboard controller; only a fleet file's `announce_as_gcs: true` makes
// it a ground station too (PX4 then sends it STATUSTEXT, and no longer sees its real ground
// station's link go: docs/fleet.md). Once the ARM is acknowledged the vehicle has had the
// HEARTBEATs the adapter sent before it.
TEST(MavlinkFlight, TheAdapterAnnouncesAGroundStationOnlyWhenTheFleetFileAsks) {
  for (bool announce : {false, true}) {
    const int port = announce ? 25394 : 25393;
    test::VehicleThread vehicle(port, 1, kSpeed);
    Flight f(port, {}, [&](fleet::DroneSettings& s) { s.announce_as_gcs = announce; });
    ASSERT_TRUE(f.drone) << f.created.message;
    ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
    auto heard = [&](uint8_t type) {
      return vehicle.inspect([type](const sim_vehicle::SimVehicle& v) { return v.heard_heartbeat_of_type(type); });
    };
    EXPECT_TRUE(heard(mavlink::mav_type::ONBOARD_CONTROLLER)) << announce;
    EXPECT_EQ(heard(mavlink::mav_type::GCS), announce);
  }
}

TEST(MavlinkFlight, TakeoffWhileDisarmedIsRefusedBeforeReachingTheAutopilot) {
  test::VehicleThread vehicle(25310, 1, kSpeed);
  Flight f(25310);
  ASSERT_TRUE(f.drone) << f.created.message;
  mid::ActionEnd e = f.fly("Takeoff", {3});
  EXPECT_EQ(e.outcome, mid::Outcome::failed);
  EXPECT_EQ(e.reason, "disarmed: arm before Takeoff");
}

// The link timeout is mission time (3 s by default), like the deadlines of the actions it
// must beat: at 4× a lost link is seen after 3 mission seconds, not after 3 wall seconds
// (12 mission seconds, longer than most motions' deadlines), when the wall-clock floor is
// below it.
TEST(MavlinkFlight, LinkLossFailsTheRunningActionAfterTheLinkTimeoutInMissionTime) {
  test::VehicleThread vehicle(25314, 1, kSpeed);
  MavlinkOptions options;
  options.link_timeout_min_wall_s = 0.5;  // 2 mission s at 4×: the 3 s timeout decides
  Flight f(25314, options);
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  ASSERT_EQ(f.fly("Takeoff", {2}).outcome, mid::Outcome::succeeded);
  std::optional<mid::ActionEnd> end;
  f.drone->start({"Hover", {}}, [&](const mid::ActionEnd& e) {
    end = e;
    f.loop.stop();
  });
  f.loop.run_until(f.loop.now() + 1.0);
  EXPECT_FALSE(end);  // Hover() runs until something stops it
  vehicle.halt();
  const double halted_at = f.loop.now();
  f.loop.run_until(f.loop.now() + 10.0);
  ASSERT_TRUE(end);
  EXPECT_LT(f.loop.now() - halted_at, 4.0);
  EXPECT_EQ(end->outcome, mid::Outcome::failed);
  EXPECT_EQ(end->reason, "link lost: no HEARTBEAT from system 1 for 3.0 s");
  EXPECT_EQ(end->failure, mid::FailureReason::link_lost);
  EXPECT_TRUE(f.drone->state().link_lost);
  mid::ActionEnd refused = f.fly("Land");
  EXPECT_EQ(refused.outcome, mid::Outcome::failed);
  EXPECT_EQ(refused.reason, "link lost: no HEARTBEAT from system 1");
  EXPECT_EQ(refused.failure, mid::FailureReason::link_lost);
}

TEST(MavlinkFlight, APilotsModeSwitchFailsTheMotionAndTheAdapterGivesWay) {
  test::VehicleThread vehicle(25320, 1, kSpeed);
  Flight f(25320);
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  ASSERT_EQ(f.fly("Takeoff", {3}).outcome, mid::Outcome::succeeded);
  std::optional<mid::ActionEnd> end;
  f.drone->start({"FlyTo", {40, 0, 3}}, [&](const mid::ActionEnd& e) {
    end = e;
    f.loop.stop();
  });
  f.loop.run_until(f.loop.now() + 1.5);  // under way in OFFBOARD
  ASSERT_FALSE(end);

  // A ground station on the same vehicle switches to POSCTL, as a pilot's switch would.
  auto gcs = ground_station_on(vehicle.port());
  ASSERT_TRUE(gcs.link) << gcs.error;
  const mavlink::CommandLong c = posctl_for(1);
  gcs.link->send(mavlink::Encoder{1, 190, 0}.encode(mavlink::pack(c)));

  f.loop.run_until(f.loop.now() + 10.0);
  ASSERT_TRUE(end);
  EXPECT_EQ(end->outcome, mid::Outcome::failed);
  EXPECT_EQ(end->reason, "the vehicle left OFFBOARD for POSCTL");
  EXPECT_EQ(end->failure, mid::FailureReason::pilot_took_over);
  EXPECT_EQ(end->detail, "mode POSCTL");
  f.loop.run_until(f.loop.now() + 2.0);  // and it does not switch back
  vehicle.halt();
  EXPECT_EQ(vehicle.mode(), sim_vehicle::Mode::manual);
}

TEST(MavlinkFlight, ForgedFramesWithTheVehiclesSystemIdFromAnotherPortAreIgnoredAndCounted) {
  test::VehicleThread vehicle(25396, 1, kSpeed);
  Flight f(25396);
  ASSERT_TRUE(f.drone) << f.created.message;
  std::vector<std::string> messages;
  f.drone->set_message_sink([&](const std::string& m) { messages.push_back(m); });
  // An attacker on the adapter's port: DENIED for every arm command and HEARTBEATs, all with
  // the vehicle's system id, while the mission arms and takes off.
  auto forger = mavlink::Link::open(*eamos::fleet::parse_link_url("udpout://127.0.0.1:25396").endpoint, [](mavlink::Frame) {});
  ASSERT_TRUE(forger.link) << forger.error;
  std::atomic<bool> stop{false};
  std::thread attack([&] {
    mavlink::Encoder forged{1, 1, 0};
    while (!stop) {
      forger.link->send(forged.encode(mavlink::pack(mavlink::CommandAck{mavlink::cmd::COMPONENT_ARM_DISARM, 2})));
      forger.link->send(forged.encode(mavlink::pack(mavlink::Heartbeat{})));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));  // a 50 Hz flood, not a wait
    }
  });
  mid::ActionEnd arm = f.fly("Arm");
  mid::ActionEnd takeoff = f.fly("Takeoff", {3});
  stop = true;
  attack.join();
  EXPECT_EQ(arm.outcome, mid::Outcome::succeeded) << arm.reason;
  EXPECT_EQ(takeoff.outcome, mid::Outcome::succeeded) << takeoff.reason;
  auto* d = dynamic_cast<MavlinkDrone*>(f.drone.get());
  ASSERT_NE(d, nullptr);
  f.loop.run_until(f.loop.now() + 0.5);  // a HEARTBEAT or two: the adapter reports the count
  std::string counted;  // the adapter's other notes (PX4 keeps its HEARTBEAT rate) come between
  for (const std::string& m : messages)
    if (counted.empty() && m.find("ignored") != std::string::npos) counted = m;
  EXPECT_NE(counted.find("datagram(s) from other addresses than system 1's"), std::string::npos)
      << (messages.empty() ? "" : messages[0]);
}

const char* kTestKey = "0f1e2d3c4b5a69788796a5b4c3d2e1f000112233445566778899aabbccddeeff";

TEST(MavlinkFlight, SigningSetupGivesTheVehicleTheKeyAndAnUnsignedGroundStationIsIgnored) {
  test::VehicleThread vehicle(25374, 1, kSpeed);
  Flight f(25374, {}, [](fleet::DroneSettings& s) {
    s.signing_key = kTestKey;
    s.signing_setup = true;
  });
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  ASSERT_EQ(f.fly("Takeoff", {3}).outcome, mid::Outcome::succeeded);
  // A ground station without the key switches the vehicle to POSCTL (as in
  // APilotsModeSwitchFailsTheMotionAndTheAdapterGivesWay): the signed vehicle drops it.
  auto gcs = ground_station_on(vehicle.port());
  ASSERT_TRUE(gcs.link) << gcs.error;
  const mavlink::CommandLong c = posctl_for(1);
  std::optional<mid::ActionEnd> end;
  f.drone->start({"FlyTo", {30, 0, 3}}, [&](const mid::ActionEnd& e) {
    end = e;
    f.loop.stop();
  });
  f.loop.run_until(f.loop.now() + 1.0);
  for (int i = 0; i < 5; ++i) gcs.link->send(mavlink::Encoder{255, 190, static_cast<uint8_t>(i)}.encode(mavlink::pack(c)));
  f.loop.run_until(f.loop.now() + 30.0);
  ASSERT_TRUE(end);
  EXPECT_EQ(end->outcome, mid::Outcome::succeeded) << end->reason;
  EXPECT_NEAR(f.drone->state().x, 30.0, 0.5);
  EXPECT_EQ(f.fly("Land").outcome, mid::Outcome::succeeded);
}

TEST(MavlinkFlight, WithAKeyButNoSetupAVehicleThatDoesNotSignNeverConnects) {
  test::VehicleThread vehicle(25375, 1, kSpeed);  // has no key: its frames are unsigned
  MavlinkOptions options;
  options.connect_timeout_s = 1.0;
  Flight f(25375, options, [](fleet::DroneSettings& s) { s.signing_key = kTestKey; });
  EXPECT_EQ(f.created.status, mid::CreateStatus::adapter_failed);
  EXPECT_NE(f.created.message.find("Signing is on for this drone"), std::string::npos) << f.created.message;
}

TEST(MavlinkFlight, OrbitRunsUntilCancelledThenHolds) {
  test::VehicleThread vehicle(25315, 1, kSpeed);
  Flight f(25315);
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  ASSERT_EQ(f.fly("Takeoff", {3}).outcome, mid::Outcome::succeeded);
  std::optional<mid::ActionEnd> end;
  mid::ActionId id = f.drone->start({"Orbit", {3}}, [&](const mid::ActionEnd& e) { end = e; });
  f.loop.run_until(f.loop.now() + 6.0);
  EXPECT_FALSE(end);
  EXPECT_FALSE(f.drone->progress(id));  // an orbit has no end to measure against
  mid::DroneState s = f.drone->state();
  EXPECT_NEAR(std::hypot(s.x, s.y), 3.0, 1.0);  // on (or near) the circle around the start
  EXPECT_TRUE(f.drone->cancel(id));
  f.loop.run_until(f.loop.now() + 0.5);
  ASSERT_TRUE(end);
  EXPECT_EQ(end->outcome, mid::Outcome::cancelled);
}

TEST(MavlinkFlight, FailsafeLandCancelsTheFlightLandsAndRefusesMore) {
  test::VehicleThread vehicle(25319, 1, kSpeed);
  Flight f(25319);
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  ASSERT_EQ(f.fly("Takeoff", {3}).outcome, mid::Outcome::succeeded);
  std::optional<mid::ActionEnd> end;
  mid::ActionId id = f.drone->start({"FlyTo", {30, 0, 3}}, [&](const mid::ActionEnd& e) { end = e; });
  f.loop.run_until(f.loop.now() + 1.5);
  ASSERT_TRUE(f.drone->progress(id));
  EXPECT_GT(*f.drone->progress(id), 0.0);  // under way ...
  EXPECT_LT(*f.drone->progress(id), 0.8);  // ... far from there
  f.drone->failsafe(fleet::Failsafe::land);
  f.loop.run_until(f.loop.now() + 0.1);
  ASSERT_TRUE(end);
  EXPECT_EQ(end->outcome, mid::Outcome::cancelled);
  EXPECT_EQ(end->reason, "failsafe: land");
  EXPECT_EQ(end->failure, mid::FailureReason::none);  // cancelled is no failure
  for (int i = 0; i < 100 && !f.drone->state().landed; ++i) f.loop.run_until(f.loop.now() + 0.5);
  EXPECT_TRUE(f.drone->state().landed);
  EXPECT_LT(f.drone->state().x, 29.0);  // landed where it was, not at the target
  mid::ActionEnd refused = f.fly("Takeoff", {3});
  EXPECT_EQ(refused.outcome, mid::Outcome::failed);
  EXPECT_EQ(refused.reason, "failsafe active (failsafe: land)");
}

// A failsafe ends with the motors off, as in the simulator, also on an autopilot that keeps
// them on after landing (here for 1000 s: ArduPilot DISARM_DELAY 0, PX4 COM_DISARM_LAND -1):
// the adapter disarms once the vehicle is down.
TEST(MavlinkFlight, FailsafeLandingEndsWithTheMotorsOffWhenTheAutopilotKeepsThemOn) {
  sim_vehicle::VehicleOptions o = test::VehicleThread::options(sim_vehicle::px4_dialect(), 1, 100.0, true);
  o.disarm_after_land_s = 1000;
  test::VehicleThread vehicle(25383, kSpeed, o);
  Flight f(25383);
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  ASSERT_EQ(f.fly("Takeoff", {3}).outcome, mid::Outcome::succeeded);
  f.drone->failsafe(fleet::Failsafe::land);
  for (int i = 0; i < 100 && !f.drone->state().landed; ++i) f.loop.run_until(f.loop.now() + 0.5);
  ASSERT_TRUE(f.drone->state().landed);
  for (int i = 0; i < 20 && f.drone->state().armed; ++i) f.loop.run_until(f.loop.now() + 0.25);
  EXPECT_FALSE(f.drone->state().armed);
}

// A goal counts as reached within the tolerance the fleet file gives the drone's type
// (`tolerance:`), not a fixed one: 3 m at any speed, a FlyByX(5) from a standstill ends while
// the vehicle is still on its way, 2-3 m short of its target.
TEST(MavlinkFlight, AGoalCountsAsReachedWithinTheToleranceTheFleetFileGivesTheType) {
  test::VehicleThread vehicle(25397, 1, kSpeed);
  Flight f(25397, {}, [](fleet::DroneSettings& s) { s.tolerance = {3.0, 0.3, 100.0}; });
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  ASSERT_EQ(f.fly("Takeoff", {3}).outcome, mid::Outcome::succeeded);
  const double from = f.drone->state().x;
  mid::ActionEnd e = f.fly("FlyByX", {5});
  ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason;
  const double flown = f.drone->state().x - from;
  EXPECT_GE(flown, 1.9);  // within 3 m of 5 m, one position report (0.1 s) late at most
  EXPECT_LT(flown, 4.0);  // the default 0.5 m would have waited for 4.5 m
}

// A motion that times out says where the vehicle stands against its goal and the type's
// tolerance, so a fleet file's `tolerance:` can be judged from the failure alone. The
// vehicle arrives; a speed bound no vehicle meets (no fleet file can give one) keeps the goal
// from counting.
TEST(MavlinkFlight, AMotionThatTimesOutSaysHowFarFromItsGoalTheVehicleStands) {
  test::VehicleThread vehicle(25398, 1, kSpeed);
  Flight f(25398, {}, [](fleet::DroneSettings& s) { s.tolerance = {0.5, 0.3, -1.0}; });
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  mid::ActionEnd e = f.fly("Takeoff", {3}, 120);
  ASSERT_EQ(e.outcome, mid::Outcome::failed) << e.reason;
  EXPECT_EQ(e.failure, mid::FailureReason::timed_out);
  EXPECT_NE(e.reason.find("timed out after"), std::string::npos) << e.reason;
  EXPECT_NE(e.reason.find(" m across, 0.0"), std::string::npos) << e.reason;  // up there, within cm
  EXPECT_NE(e.reason.find("its goal, at 0.0"), std::string::npos) << e.reason;
  EXPECT_NE(e.reason.find("the type's tolerance: 0.50 m, 0.30 m, -1.00 m/s"), std::string::npos) << e.reason;
}

// The auto-disarm striking as the takeoff goes out (ArduCopter SITL: DISARM_DELAY ran out
// 40 ms before Listing 2's Takeoff, eamos' last HEARTBEAT still armed): the vehicle disarms
// and refuses the NAV_TAKEOFF. The Takeoff arms again and repeats it, once, and flies.
TEST(MavlinkFlight, ATakeoffRefusedAsTheAutoDisarmStrikesIsArmedAgainAndRepeatedOnce) {
  sim_vehicle::VehicleOptions o = test::VehicleThread::options(sim_vehicle::ardupilot_dialect(), 1, 100.0, true);
  o.disarm_at_first_takeoff = true;
  test::VehicleThread vehicle(25399, kSpeed, o);
  Flight f(25399);
  ASSERT_TRUE(f.drone) << f.created.message;
  std::vector<std::string> said;
  f.drone->set_message_sink([&](const std::string& text) { said.push_back(text); });
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  mid::ActionEnd e = f.fly("Takeoff", {3});
  std::string all;
  for (const std::string& s : said) all += s + "\n";
  ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << e.reason << "\n" << all;
  EXPECT_NEAR(f.drone->state().z, 3.0, 0.3);
  EXPECT_TRUE(f.drone->state().armed);
  bool repeated = false;
  for (const std::string& s : said) repeated = repeated || s.find("eamos repeats it, once") != std::string::npos;
  EXPECT_TRUE(repeated);
}

// The autopilot's auto-disarm on the ground, struck right after a HEARTBEAT: one that waits
// for the next HEARTBEAT sees it a whole period late.
struct DisarmSeen {
  double after_s = NAN;  ///< from the vehicle's text to the adapter showing it disarmed; NaN: never
  int heartbeat_requests = 0;  ///< MAV_CMD_REQUEST_MESSAGE the vehicle received
  std::string why;             ///< what went wrong, when after_s is NaN
};

DisarmSeen auto_disarm_seen(const sim_vehicle::Dialect& dialect, int port) {
  sim_vehicle::VehicleOptions o = test::VehicleThread::options(dialect, 1, 100.0, true);
  o.preflight_disarm_s = 2.0;
  test::VehicleThread vehicle(port, kSpeed, o);
  Flight f(port);
  if (!f.drone) return {.why = f.created.message};
  std::optional<double> text_at;
  f.drone->set_message_sink([&](const std::string& text) {
    if (text.find("Disarmed by auto preflight disarming") != std::string::npos) text_at = f.loop.now();
  });
  if (f.fly("Arm").outcome != mid::Outcome::succeeded) return {.why = "Arm failed"};
  double give_up = f.loop.now() + 10;
  while (f.drone->state().armed && f.loop.now() < give_up) f.loop.run_until(f.loop.now() + 0.01);
  if (f.drone->state().armed || !text_at) return {.why = "no auto-disarm seen"};
  return {.after_s = f.loop.now() - *text_at,
          .heartbeat_requests =
              vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.received(mavlink::cmd::REQUEST_MESSAGE); })};
}

// PX4 keeps its HEARTBEAT at 1 Hz (it answers SET_MESSAGE_INTERVAL for it MAV_RESULT_FAILED),
// and armed state comes only with a HEARTBEAT: on the ground the adapter asks for one at
// 20 Hz. (The vehicle's text is the test's clock of the disarm; PX4 sends it only to a
// ground station's link.)
TEST(MavlinkFlight, AnAutoDisarmIsSeenAtOnceFromAnAutopilotThatKeepsItsHeartbeatRate) {
  DisarmSeen seen = auto_disarm_seen(sim_vehicle::px4_dialect(), 25407);
  ASSERT_FALSE(std::isnan(seen.after_s)) << seen.why;
  EXPECT_LT(seen.after_s, 0.3) << "a HEARTBEAT waited for is 1 s late";
  EXPECT_GE(seen.heartbeat_requests, 1);
}

// ArduPilot streams HEARTBEAT at the 20 Hz asked for: the disarm shows with the next one.
TEST(MavlinkFlight, AnAutoDisarmIsSeenAtOnceFromAnAutopilotThatStreamsHeartbeatsFast) {
  DisarmSeen seen = auto_disarm_seen(sim_vehicle::ardupilot_dialect(), 25408);
  ASSERT_FALSE(std::isnan(seen.after_s)) << seen.why;
  EXPECT_LT(seen.after_s, 0.3);
  EXPECT_EQ(seen.heartbeat_requests, 0);
}

// A takeoff the autopilot refuses for its own reason (here an altitude it will not fly) is
// repeated once, as the auto-disarm race asks, and then fails with the autopilot's answer.
TEST(MavlinkFlight, ATakeoffTheAutopilotRefusesTwiceFailsWithItsAnswer) {
  test::VehicleThread vehicle(25406, 1, kSpeed);
  Flight f(25406, {}, [](fleet::DroneSettings& s) { s.limits.max_altitude_m = 500; });
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  mid::ActionEnd e = f.fly("Takeoff", {150});  // the vehicle takes off to 120 m at most
  EXPECT_EQ(e.outcome, mid::Outcome::failed);
  EXPECT_EQ(e.failure, mid::FailureReason::refused);
  EXPECT_EQ(e.reason, "refused by PX4: MAV_CMD_NAV_TAKEOFF: MAV_RESULT_DENIED (denied by the autopilot)");
  EXPECT_EQ(vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.received(mavlink::cmd::NAV_TAKEOFF); }), 2);
  EXPECT_TRUE(f.drone->state().landed);
}

TEST(MavlinkAdapter, NoVehicleIsACreateErrorThatSaysWhatToCheck) {
  MavlinkOptions options;
  options.connect_timeout_s = 0.3;
  Flight f(25316, options);
  EXPECT_EQ(f.created.status, mid::CreateStatus::adapter_failed);
  EXPECT_NE(f.created.message.find("no HEARTBEAT from system 1 on udp://127.0.0.1:25316"),
            std::string::npos)
      << f.created.message;
}

TEST(MavlinkAdapter, VirtualTimeAndMissingConnectionAreRefused) {
  mid::EventLoop loop;
  mid::AdapterRegistry registry;
  register_adapter(registry);  // real_time = false
  fleet::DroneSettings s;
  s.name = "Drone1";
  s.connection = "udp://:25317";
  auto r = registry.create("mavlink", s, fleet::generic_multirotor("Quad"), loop);
  EXPECT_NE(r.message.find("--realtime"), std::string::npos) << r.message;

  mid::AdapterRegistry live;
  register_adapter(live, {.real_time = true});
  s.connection = "";
  r = live.create("mavlink", s, fleet::generic_multirotor("Quad"), loop);
  EXPECT_NE(r.message.find("no `connection:`"), std::string::npos) << r.message;
  s.connection = "udp:14540";
  r = live.create("mavlink", s, fleet::generic_multirotor("Quad"), loop);
  EXPECT_NE(r.message.find("no scheme"), std::string::npos) << r.message;
}


// Separation predicts a drone along the line to its goal (mid::Drone::motion_goal): a FlyTo's
// target while it flies, the ground below for a Land, none once it ended.
TEST(MavlinkFlight, TheGoalOfTheRunningMotionIsItsTargetAndGoneWithIt) {
  test::VehicleThread vehicle(25447, 1, kSpeed);
  Flight f(25447);
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  ASSERT_EQ(f.fly("Takeoff", {3}).outcome, mid::Outcome::succeeded);
  EXPECT_FALSE(f.drone->motion_goal().has_value());
  bool ended = false;
  f.drone->start({"FlyTo", {6, 2, 3}}, [&](const mid::ActionEnd&) { ended = true; });
  f.loop.run_until(f.loop.now() + 0.5);
  ASSERT_FALSE(ended);
  ASSERT_TRUE(f.drone->motion_goal().has_value());
  EXPECT_NEAR(f.drone->motion_goal()->x, 6.0, 1e-9);
  EXPECT_NEAR(f.drone->motion_goal()->y, 2.0, 1e-9);
  EXPECT_NEAR(f.drone->motion_goal()->z, 3.0, 1e-9);
  for (int i = 0; !ended && i < 120; ++i) f.loop.run_until(f.loop.now() + 0.5);
  ASSERT_TRUE(ended);
  EXPECT_FALSE(f.drone->motion_goal().has_value());
  f.drone->start({"Land", {}}, [](const mid::ActionEnd&) {});
  f.loop.run_until(f.loop.now() + 0.5);
  ASSERT_TRUE(f.drone->motion_goal().has_value());
  EXPECT_NEAR(f.drone->motion_goal()->z, 0.0, 1e-9);
}

}  // namespace
}  // namespace eamos::mavlink_adapter
