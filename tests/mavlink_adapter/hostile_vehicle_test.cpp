// The adapter against a "vehicle" that is a raw MAVLink link of the test's own, answering
// with what no autopilot sends: what the adapter must not believe.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include "flight.h"
#include "mavlink/enums.h"
#include "mavlink/link.h"
#include "mavlink/payloads.h"

namespace eamos::mavlink_adapter {
namespace {

namespace ml = eamos::mavlink;

// Answers every COMMAND_LONG with a COMMAND_ACK whose MAV_RESULT is `result`, and sends a
// PX4 HEARTBEAT at 10 Hz (an autopilot's beat, on its own thread) until destroyed.
class ScriptedVehicle {
 public:
  ScriptedVehicle(int port, uint8_t result) : result_(result) {
    auto opened = ml::Link::open(*ml::parse_url("udpout://127.0.0.1:" + std::to_string(port)).endpoint,
                                 [this](ml::Frame f) { on_frame(f); });
    if (!opened.link) throw std::runtime_error(opened.error);
    link_ = std::move(opened.link);
    beat_ = std::thread([this] {
      std::unique_lock lock(mutex_);
      while (!stopping_) {
        link_->send(encoder_.encode(heartbeat()));
        stop_.wait_for(lock, std::chrono::milliseconds(100));
      }
    });
  }
  ~ScriptedVehicle() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    stop_.notify_all();
    beat_.join();
  }
  int commands_seen() {
    std::lock_guard lock(mutex_);
    return commands_;
  }

 private:
  static ml::Message heartbeat() {
    ml::Heartbeat hb;
    hb.type = 2;  // MAV_TYPE_QUADROTOR
    hb.autopilot = ml::autopilot::PX4;
    return ml::pack(hb);
  }
  void send(const ml::Message& m) {
    std::lock_guard lock(mutex_);
    link_->send(encoder_.encode(m));
  }
  void on_frame(const ml::Frame& f) {
    if (auto c = ml::unpack_command_long(f.message)) {
      {
        std::lock_guard lock(mutex_);
        ++commands_;
      }
      ml::CommandAck ack;
      ack.command = c->command;
      ack.result = result_;
      ack.target_system = f.sysid;
      ack.target_component = f.compid;
      send(ml::pack(ack));
    }
  }

  uint8_t result_;
  std::mutex mutex_;
  ml::Encoder encoder_{1, 1};
  int commands_ = 0;
  bool stopping_ = false;
  std::condition_variable stop_;
  std::thread beat_;
  std::unique_ptr<ml::Link> link_;  // last: destroyed first, so no handler runs after the rest
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

}  // namespace
}  // namespace eamos::mavlink_adapter
