// The simulated vehicle keeps the PX4 rules the adapter depends on, seen from the wire: a test
// plays the companion computer with a raw link on loopback UDP.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../mavlink_adapter/vehicle_thread.h"
#include "mavlink/enums.h"
#include "mavlink/link.h"
#include "mavlink/payloads.h"

namespace eamos::sim_vehicle {
namespace {

namespace ml = eamos::mavlink;
namespace px4 = eamos::mavlink::px4;
constexpr double kSpeed = 4.0;

/// The companion's side: every frame the vehicle sends, and a way to wait for one.
class Companion {
 public:
  explicit Companion(int port) {
    ml::OpenResult r = ml::Link::open(*eamos::fleet::parse_link_url("udp://127.0.0.1:" + std::to_string(port)).endpoint,
                                      [this](ml::Frame f) {
                                        std::lock_guard lock(m_);
                                        frames_.push_back(std::move(f));
                                        cv_.notify_all();
                                      });
    link_ = std::move(r.link);
  }

  /// Waits (bounded) for the next frame after `from` that `pick` accepts; its index or -1.
  template <typename Pick>
  int wait_for(size_t from, Pick pick) {
    std::unique_lock lock(m_);
    int found = -1;
    cv_.wait_for(lock, std::chrono::seconds(5), [&] {
      for (size_t i = from; i < frames_.size(); ++i)
        if (pick(frames_[i].message)) return (found = static_cast<int>(i)) >= 0;
      return false;
    });
    return found;
  }
  size_t count() {
    std::lock_guard lock(m_);
    return frames_.size();
  }
  ml::Message frame(int i) {
    std::lock_guard lock(m_);
    return frames_[i].message;
  }

  /// Sends a command and returns the MAV_RESULT of its ACK (255: none came).
  uint8_t command(uint16_t id, std::array<float, 7> params = {}, uint8_t confirmation = 0) {
    size_t from = count();
    ml::CommandLong c;
    c.target_system = 1;
    c.target_component = 1;
    c.command = id;
    c.confirmation = confirmation;
    c.param = params;
    send(ml::pack(c));
    int i = wait_for(from, [&](const ml::Message& m) {
      auto a = ml::unpack_command_ack(m);
      return a && a->command == id;
    });
    return i < 0 ? 255 : ml::unpack_command_ack(frame(i))->result;
  }
  void send(const ml::Message& m) {
    // A port another test run holds leaves no link: the case fails here, not on a null call.
    if (!link_) {
      ADD_FAILURE() << "the companion could not open its UDP port";
      return;
    }
    link_->send(encoder_.encode(m));
  }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  std::vector<ml::Frame> frames_;
  ml::Encoder encoder_{1, ml::comp::ONBOARD_COMPUTER, 0};
  std::unique_ptr<ml::Link> link_;
};

void await_first_frame(Companion& c) {
  // The vehicle sends first (like PX4 SITL); until then the companion has nobody to answer.
  ASSERT_GE(c.wait_for(0, [](const ml::Message& m) { return m.id == ml::msg::HEARTBEAT; }), 0);
}

ml::SetPositionTargetLocalNed setpoint(float north, float east, float down) {
  ml::SetPositionTargetLocalNed sp;
  sp.target_system = 1;
  sp.target_component = 1;
  sp.type_mask = ml::kPositionOnlyMask;
  sp.x = north;
  sp.y = east;
  sp.z = down;
  return sp;
}

TEST(SimVehicle, RefusesOffboardUntilSetpointsStream) {
  Companion companion(25341);
  test::VehicleThread vehicle(25341, 1, kSpeed);
  await_first_frame(companion);
  auto offboard = ml::px4::OFFBOARD;
  std::array<float, 7> params{1, float((offboard >> 16) & 0xFF), 0};
  EXPECT_EQ(companion.command(ml::cmd::DO_SET_MODE, params), ml::result::DENIED);
  companion.send(ml::pack(setpoint(0, 0, 0)));
  EXPECT_EQ(companion.command(ml::cmd::DO_SET_MODE, params), ml::result::ACCEPTED);
  size_t from = companion.count();
  int hb = companion.wait_for(from, [&](const ml::Message& m) {
    auto h = ml::unpack_heartbeat(m);
    return h && h->custom_mode == offboard;
  });
  EXPECT_GE(hb, 0);
}

TEST(SimVehicle, RefusesTakeoffWhileDisarmed) {
  Companion companion(25342);
  test::VehicleThread vehicle(25342, 1, kSpeed);
  await_first_frame(companion);
  EXPECT_EQ(companion.command(ml::cmd::NAV_TAKEOFF, {0, 0, 0, 0, NAN, NAN, 491}), ml::result::DENIED);
  EXPECT_EQ(companion.command(ml::cmd::COMPONENT_ARM_DISARM, {1}), ml::result::ACCEPTED);
  EXPECT_EQ(companion.command(ml::cmd::NAV_TAKEOFF, {0, 0, 0, 0, NAN, NAN, 491}), ml::result::ACCEPTED);
}

TEST(SimVehicle, AcknowledgesAResendWithoutExecutingItTwice) {
  Companion companion(25343);
  test::VehicleThread vehicle(25343, 1, kSpeed);
  await_first_frame(companion);
  ASSERT_EQ(companion.command(ml::cmd::COMPONENT_ARM_DISARM, {1}), ml::result::ACCEPTED);
  std::array<float, 7> takeoff{0, 0, 0, 0, NAN, NAN, 493};
  ASSERT_EQ(companion.command(ml::cmd::NAV_TAKEOFF, takeoff), ml::result::ACCEPTED);
  size_t from = companion.count();
  ASSERT_GE(companion.wait_for(from, [](const ml::Message& m) {
    auto e = ml::unpack_extended_sys_state(m);
    return e && e->landed_state != ml::landed::ON_GROUND;
  }), 0);
  // In the air now: a new takeoff is refused, but a resend of the first is acknowledged again.
  EXPECT_EQ(companion.command(ml::cmd::NAV_TAKEOFF, takeoff, 1), ml::result::ACCEPTED);
  EXPECT_EQ(companion.command(ml::cmd::NAV_TAKEOFF, takeoff, 0), ml::result::DENIED);
}

TEST(SimVehicle, AnswersUnknownCommandsAsUnsupported) {
  Companion companion(25344);
  test::VehicleThread vehicle(25344, 1, kSpeed);
  await_first_frame(companion);
  EXPECT_EQ(companion.command(31000), ml::result::UNSUPPORTED);
}

/// DO_ORBIT around where the vehicle is: radius (negative = counter-clockwise), speed.
std::array<float, 7> orbit(float radius, float speed = 2) { return {radius, speed, 0, NAN, NAN, NAN, NAN}; }

TEST(SimVehicle, Px4FliesDoOrbitInTheAirInItsOrbitMode) {
  Companion companion(25345);
  test::VehicleThread vehicle(25345, 1, kSpeed);
  await_first_frame(companion);
  ASSERT_EQ(companion.command(ml::cmd::COMPONENT_ARM_DISARM, {1}), ml::result::ACCEPTED);
  EXPECT_EQ(companion.command(ml::cmd::DO_ORBIT, orbit(-3)), ml::result::DENIED);  // on the ground
  ASSERT_EQ(companion.command(ml::cmd::NAV_TAKEOFF, {0, 0, 0, 0, NAN, NAN, 491}), ml::result::ACCEPTED);
  ASSERT_GE(companion.wait_for(companion.count(), [](const ml::Message& m) {
    auto e = ml::unpack_extended_sys_state(m);
    return e && e->landed_state == ml::landed::IN_AIR;
  }), 0);
  EXPECT_EQ(companion.command(ml::cmd::DO_ORBIT, orbit(-3)), ml::result::ACCEPTED);
  int hb = companion.wait_for(companion.count(), [](const ml::Message& m) {
    auto h = ml::unpack_heartbeat(m);
    return h && h->custom_mode == px4::ORBIT;
  });
  EXPECT_GE(hb, 0);
  EXPECT_EQ(vehicle.inspect([](const SimVehicle& v) { return v.mode(); }), Mode::orbit);
}

/// Arms the PX4-like vehicle and takes it off (to 491 m AMSL, 3 m up), until it reports
/// itself in the air. Fatal failures: call through ASSERT_NO_FATAL_FAILURE.
void arm_and_climb(Companion& companion) {
  ASSERT_EQ(companion.command(ml::cmd::COMPONENT_ARM_DISARM, {1}), ml::result::ACCEPTED);
  ASSERT_EQ(companion.command(ml::cmd::NAV_TAKEOFF, {0, 0, 0, 0, NAN, NAN, 491}), ml::result::ACCEPTED);
  ASSERT_GE(companion.wait_for(companion.count(), [](const ml::Message& m) {
    auto e = ml::unpack_extended_sys_state(m);
    return e && e->landed_state == ml::landed::IN_AIR;
  }), 0);
}

// As PX4 (its Orbit task sets the centre only when it starts): DO_ORBIT again in the Orbit
// mode changes the radius around the same centre, it does not start a new orbit where the
// vehicle is.
TEST(SimVehicle, Px4DoOrbitSentAgainInOrbitModeKeepsTheCentreAndTakesTheNewRadius) {
  Companion companion(25348);
  test::VehicleThread vehicle(25348, 1, kSpeed);
  await_first_frame(companion);
  ASSERT_NO_FATAL_FAILURE(arm_and_climb(companion));
  ASSERT_EQ(companion.command(ml::cmd::SET_MESSAGE_INTERVAL, {float(ml::msg::LOCAL_POSITION_NED), 2e5f}),
            ml::result::ACCEPTED);
  auto where = [&] { return vehicle.inspect([](const SimVehicle& v) { return v.drone().state(); }); };
  const mid::DroneState start = where();
  auto within = [&](double radius) {  // a position report this far from the start
    return [&start, radius](const ml::Message& m) {
      auto p = ml::unpack_local_position_ned(m);
      return p && std::fabs(std::hypot(p->y - start.x, p->x - start.y) - radius) < 0.2;
    };
  };
  ASSERT_EQ(companion.command(ml::cmd::DO_ORBIT, orbit(-3)), ml::result::ACCEPTED);
  ASSERT_GE(companion.wait_for(companion.count(), within(3.0)), 0);
  ASSERT_EQ(companion.command(ml::cmd::DO_ORBIT, orbit(-3.5)), ml::result::ACCEPTED);
  int on_new_circle = companion.wait_for(companion.count(), within(3.5));
  ASSERT_GE(on_new_circle, 0);
  // Then on it for the next ten reports (2 s, a third of a turn): around the first centre.
  int from = on_new_circle + 1;
  for (int k = 0; k < 10; ++k) {
    int next = companion.wait_for(from, [](const ml::Message& m) { return ml::unpack_local_position_ned(m).has_value(); });
    ASSERT_GE(next, 0);
    EXPECT_TRUE(within(3.5)(companion.frame(next))) << "report " << k;
    from = next + 1;
  }
  EXPECT_EQ(vehicle.inspect([](const SimVehicle& v) { return v.mode(); }), Mode::orbit);
}

TEST(SimVehicle, Px4RefusesAnOrbitLargerThanItsLargest) {
  Companion companion(25346);
  test::VehicleThread vehicle(25346, 1, kSpeed);
  await_first_frame(companion);
  ASSERT_NO_FATAL_FAILURE(arm_and_climb(companion));
  EXPECT_EQ(companion.command(ml::cmd::DO_ORBIT, orbit(2000)), ml::result::DENIED);
}

TEST(SimVehicle, ArduPilotAnswersDoOrbitAsUnsupported) {
  Companion companion(25347);
  test::VehicleThread vehicle(25347, 1, kSpeed, ardupilot_dialect());
  await_first_frame(companion);
  EXPECT_EQ(companion.command(ml::cmd::DO_ORBIT, orbit(-3)), ml::result::UNSUPPORTED);
}

// `eamos sim-vehicle --gcs`: a ground station (here the project's own MAVLink reader, where
// QGroundControl listens on 14550) sees the vehicle the companion flies: its heartbeat and
// its climb after the companion's takeoff.
TEST(SimVehicle, AGroundStationSeesTheVehicleTheCompanionFlies) {
  // Ports of its own: ctest runs the cases of this suite side by side.
  Companion companion(25360);
  Companion ground_station(25361);
  pid_t pid = fork();
  if (pid == 0) {
    execl(EAMOS_BINARY, EAMOS_BINARY, "sim-vehicle", "--udp", "25360", "--gcs", "udpout://127.0.0.1:25361",
          "--speed", "4", "--duration", "40", static_cast<char*>(nullptr));
    _exit(127);
  }
  ASSERT_GT(pid, 0);
  await_first_frame(companion);
  EXPECT_GE(ground_station.wait_for(0, [](const ml::Message& m) {
    auto h = ml::unpack_heartbeat(m);
    return h && h->autopilot == ml::autopilot::PX4;
  }), 0) << "no heartbeat at the ground station";
  ASSERT_EQ(companion.command(ml::cmd::COMPONENT_ARM_DISARM, {1}), ml::result::ACCEPTED);
  ASSERT_EQ(companion.command(ml::cmd::NAV_TAKEOFF, {0, 0, 0, 0, NAN, NAN, 491}), ml::result::ACCEPTED);
  int climbed = ground_station.wait_for(0, [](const ml::Message& m) {
    auto p = ml::unpack_global_position_int(m);
    return p && p->relative_alt > 1000;
  });
  EXPECT_GE(climbed, 0) << "the ground station never saw the vehicle above 1 m";
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

}  // namespace
}  // namespace eamos::sim_vehicle
