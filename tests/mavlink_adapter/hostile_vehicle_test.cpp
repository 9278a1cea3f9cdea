// The adapter against a "vehicle" that is a raw MAVLink link of the test's own, answering
// with what no autopilot sends: what the adapter must not believe.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "flight.h"
#include "mavlink/enums.h"
#include "mavlink/link.h"
#include "mavlink/payloads.h"

namespace eamos::mavlink_adapter {
namespace {

namespace ml = eamos::mavlink;

// A raw MAVLink link of the test's own to the adapter's port, and a beat: a callback every
// 100 ms on its own thread (an autopilot's HEARTBEAT), holding mutex(), until destroyed.
// A vehicle keeps it as its last member: destroyed first, so no handler or beat runs after
// the rest of the vehicle is gone.
class RawLink {
 public:
  RawLink(int port, std::function<void(ml::Frame)> on_frame) {
    auto opened = ml::Link::open(*eamos::fleet::parse_link_url("udpout://127.0.0.1:" + std::to_string(port)).endpoint,
                                 std::move(on_frame));
    if (!opened.link) throw std::runtime_error(opened.error);
    link_ = std::move(opened.link);
  }
  ~RawLink() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    stop_.notify_all();
    if (beat_.joinable()) beat_.join();
  }
  void start_beat(std::function<void()> beat) {
    beat_ = std::thread([this, beat = std::move(beat)] {
      std::unique_lock lock(mutex_);
      while (!stopping_) {
        beat();
        stop_.wait_for(lock, std::chrono::milliseconds(100));
      }
    });
  }
  std::mutex& mutex() { return mutex_; }
  void send_locked(const ml::Message& m) { link_->send(encoder_.encode(m)); }  ///< with mutex() held

 private:
  std::mutex mutex_;
  ml::Encoder encoder_{1, 1};
  bool stopping_ = false;
  std::condition_variable stop_;
  std::thread beat_;
  std::unique_ptr<ml::Link> link_;
};

/// The COMMAND_ACK a vehicle sends for `f`'s COMMAND_LONG, with `result`.
ml::Message ack_of(const ml::Frame& f, const ml::CommandLong& c, uint8_t result) {
  ml::CommandAck ack;
  ack.command = c.command;
  ack.result = result;
  ack.target_system = f.sysid;
  ack.target_component = f.compid;
  return ml::pack(ack);
}

// Answers every COMMAND_LONG with a COMMAND_ACK whose MAV_RESULT is `result`, and sends a
// PX4 HEARTBEAT at 10 Hz (an autopilot's beat, on its own thread) until destroyed.
class ScriptedVehicle {
 public:
  ScriptedVehicle(int port, uint8_t result) : result_(result), link_(port, [this](ml::Frame f) { on_frame(f); }) {
    link_.start_beat([this] { link_.send_locked(heartbeat()); });
  }
  int commands_seen() {
    std::lock_guard lock(link_.mutex());
    return commands_;
  }

 private:
  static ml::Message heartbeat() {
    ml::Heartbeat hb;
    hb.type = 2;  // MAV_TYPE_QUADROTOR
    hb.autopilot = ml::autopilot::PX4;
    return ml::pack(hb);
  }
  void on_frame(const ml::Frame& f) {
    auto c = ml::unpack_command_long(f.message);
    if (!c) return;
    std::lock_guard lock(link_.mutex());
    ++commands_;
    link_.send_locked(ack_of(f, *c, result_));
  }

  uint8_t result_;
  int commands_ = 0;
  RawLink link_;  // last
};

// MAV_RESULT ends at 9; an ACK with 200 means nothing, so it must neither accept nor refuse
// the command: it is dropped and the command sent again, until the action's own timeout
// (or the sender's last try) ends it. Taken as an answer it was a refusal at once.
TEST(HostileVehicle, AckWithAnUnknownResultIsDroppedAndTheCommandEndsUnanswered) {
  ScriptedVehicle vehicle(25331, 200);
  test::Flight f(25331);
  ASSERT_TRUE(f.drone) << f.created.message;
  mid::ActionEnd e = f.fly("Arm");
  EXPECT_EQ(e.outcome, mid::Outcome::failed);
  EXPECT_EQ(e.reason.find("refused"), std::string::npos) << e.reason;
  EXPECT_TRUE(e.reason.find("timed out") != std::string::npos ||
              e.reason.find("no COMMAND_ACK after") != std::string::npos)
      << e.reason;
  EXPECT_FALSE(f.drone->state().armed);
  EXPECT_GE(vehicle.commands_seen(), 2) << "the command was not sent again";
}

// The same vehicle answering a known result (MAV_RESULT_FAILED) is believed: the harness
// reaches the adapter, so the test above fails for the reason it names.
TEST(HostileVehicle, AckWithAKnownResultIsTakenAsTheAnswer) {
  ScriptedVehicle vehicle(25332, 4);  // MAV_RESULT_FAILED
  test::Flight f(25332);
  ASSERT_TRUE(f.drone) << f.created.message;
  mid::ActionEnd e = f.fly("Arm");
  EXPECT_EQ(e.outcome, mid::Outcome::failed);
  EXPECT_NE(e.reason.find("MAV_RESULT_FAILED"), std::string::npos) << e.reason;
}

// A PX4 in OFFBOARD, armed, 3 m up (LOCAL_POSITION_NED and HEARTBEAT at 10 Hz, no
// EXTENDED_SYS_STATE), accepting every command, until knock_down(): then disarmed at 0 m, in
// the same mode, as after a kill switch or a crash the mission did not ask for.
class DownedVehicle {
 public:
  explicit DownedVehicle(int port) : link_(port, [this](ml::Frame f) { on_frame(f); }) {
    link_.start_beat([this] {
      ml::Heartbeat hb;
      hb.type = 2;  // MAV_TYPE_QUADROTOR
      hb.autopilot = ml::autopilot::PX4;
      hb.base_mode = ml::mode_flag::CUSTOM_MODE_ENABLED | (down_ ? 0 : ml::mode_flag::SAFETY_ARMED);
      hb.custom_mode = ml::px4::OFFBOARD;
      link_.send_locked(ml::pack(hb));
      ml::LocalPositionNed p;
      p.z = down_ ? 0.0f : -3.0f;
      link_.send_locked(ml::pack(p));
    });
  }
  void knock_down() {
    std::lock_guard lock(link_.mutex());
    down_ = true;
  }

 private:
  void on_frame(const ml::Frame& f) {
    auto c = ml::unpack_command_long(f.message);
    if (!c) return;
    std::lock_guard lock(link_.mutex());
    link_.send_locked(ack_of(f, *c, 0));  // MAV_RESULT_ACCEPTED
  }

  bool down_ = false;
  RawLink link_;  // last
};

// An endless motion (Hover(), Orbit) has no deadline: on a vehicle that is down and disarmed
// without the mission landing it, it must fail, or it would run for ever, and a mission that
// waited for it (a DoUntil watching something else, an async branch) with it, to its time limit.
TEST(HostileVehicle, EndlessMotionFailsWhenTheVehicleIsDownAndDisarmedByItself) {
  DownedVehicle vehicle(25333);
  MavlinkOptions quick;
  quick.param_timeout_s = 0.2;  // it answers no PARAM_REQUEST_READ: do not wait 3 s for them
  test::Flight f(25333, quick);
  ASSERT_TRUE(f.drone) << f.created.message;
  mid::SubscriptionId flying = f.drone->subscribe([&](const mid::DroneState& s) {
    if (s.armed && !s.landed) f.loop.stop();
  });
  f.loop.run_until(f.loop.now() + 60.0);  // until its telemetry says it flies
  f.drone->unsubscribe(flying);
  ASSERT_TRUE(f.drone->state().armed);
  std::optional<mid::ActionEnd> end;
  f.drone->start({"Hover", {}}, [&](const mid::ActionEnd& e) {
    end = e;
    f.loop.stop();
  });
  f.loop.run_until(f.loop.now() + 1.0);  // hovering, streaming setpoints in OFFBOARD
  ASSERT_FALSE(end) << end->reason;
  vehicle.knock_down();
  f.loop.run_until(f.loop.now() + 60.0);  // stopped by the end; the bound only if it never comes
  ASSERT_TRUE(end) << "Hover() still running on a vehicle down and disarmed";
  EXPECT_EQ(end->outcome, mid::Outcome::failed);
  EXPECT_EQ(end->failure, mid::FailureReason::vehicle_fault);
  EXPECT_EQ(end->reason, "PX4 reports the vehicle on the ground and disarmed while Hover ran: it cannot go on");
  EXPECT_EQ(end->detail, "landed and disarmed");
}

}  // namespace
}  // namespace eamos::mavlink_adapter
