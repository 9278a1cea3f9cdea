// A MAVLink attacker on the adapter's port (docs/security.md):
// while `eamos run` flies a real `eamos sim-vehicle` process over loopback UDP, another
// sender (this test's own socket, another address than the vehicle's) floods the adapter's
// listening port with garbage and with forged frames carrying the vehicle's system id:
// HEARTBEATs and COMMAND_ACK DENIED for every command the flight sends. A listening link that
// followed any datagram's sender would send our commands to the attacker and its DENIED
// would fail the mission. Expected: not one datagram reaches the attacker, the flight
// completes, and the foreign datagrams are counted and logged. Port 25366.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "mavlink/enums.h"
#include "mavlink/frame.h"
#include "mavlink/payloads.h"
#include "support/eamos_process.h"

namespace {

namespace fs = std::filesystem;
namespace ml = eamos::mavlink;

/// A UDP socket on 127.0.0.1 (a port of its own) that floods `port` and counts what it
/// is sent back.
class Attacker {
 public:
  explicit Attacker(int port) {
    fd_ = socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in self{};
    self.sin_family = AF_INET;
    self.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    bind(fd_, reinterpret_cast<sockaddr*>(&self), sizeof self);
    fcntl(fd_, F_SETFL, O_NONBLOCK);
    target_.sin_family = AF_INET;
    target_.sin_port = htons(static_cast<uint16_t>(port));
    target_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  ~Attacker() {
    stop();
    close(fd_);
  }
  void start() {
    flood_ = std::thread([this] {
      while (!stopping_) {
        send_round();
        drain();
        std::this_thread::sleep_for(std::chrono::milliseconds(20));  // a 50 Hz flood, not a wait
      }
      drain();
    });
  }
  void stop() {
    stopping_ = true;
    if (flood_.joinable()) flood_.join();
  }
  std::uint64_t sent() const { return sent_; }
  std::uint64_t received() const { return received_; }

 private:
  void send(const std::vector<uint8_t>& bytes) {
    if (sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&target_), sizeof target_) > 0)
      ++sent_;
  }
  // Garbage, then what an autopilot with the vehicle's system id would say to refuse.
  void send_round() {
    std::vector<uint8_t> junk(40);
    for (uint8_t& b : junk) b = static_cast<uint8_t>(random_());
    junk[0] = 0xFD;  // looks like the start of a MAVLink 2 frame
    send(junk);
    ml::Heartbeat hb;
    hb.type = 2;  // MAV_TYPE_QUADROTOR
    hb.autopilot = ml::autopilot::PX4;
    send(vehicle_.encode(ml::pack(hb)));
    for (uint16_t command : {ml::cmd::COMPONENT_ARM_DISARM, ml::cmd::NAV_TAKEOFF, ml::cmd::NAV_LAND, ml::cmd::DO_SET_MODE})
      send(vehicle_.encode(ml::pack(ml::CommandAck{command, ml::result::DENIED})));
  }
  void drain() {
    uint8_t buf[2048];
    while (recv(fd_, buf, sizeof buf, 0) > 0) ++received_;
  }

  int fd_ = -1;
  sockaddr_in target_{};
  ml::Encoder vehicle_{1, 1, 0};  // the vehicle's system and component id
  std::mt19937 random_{7};
  std::thread flood_;
  std::atomic<bool> stopping_{false};
  std::atomic<std::uint64_t> sent_{0}, received_{0};
};

TEST(MavlinkAttacker, FramesFromAnotherAddressAreIgnoredCountedAndGetNothingBack) {
  const int port = 25366;
  fs::path dir = fs::temp_directory_path() / ("eamos-mav-attacker-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "fleet.yaml") << "drones:\n  Drone1: {adapter: mavlink, connection: \"udp://127.0.0.1:" << port
                                    << "\", sysid: 1}\n";
  eamos_test::EamosProcess vehicle = eamos_test::start_eamos(
      {"sim-vehicle", "--udp", std::to_string(port), "--sysid", "1", "--speed", "4", "--duration", "120"});
  ASSERT_TRUE(eamos_test::read_until(vehicle, "receiving on port ")) << vehicle.seen;
  eamos_test::EamosProcess run = eamos_test::start_eamos(
      {"run", std::string(EAMOS_TEST_DATA) + "/data/short-flight.eamos", "--fleet", (dir / "fleet.yaml").string(),
       "--speed", "4", "--time-limit", "60"});
  // From the takeoff on (the link has followed the vehicle by then) until the flight ended.
  Attacker attacker(port);
  ASSERT_TRUE(eamos_test::read_until(run, "Drone1.Takeoff(3)")) << run.seen;
  attacker.start();
  eamos_test::read_until(run, "Drone1.Disarm()  succeeded");
  attacker.stop();
  eamos_test::Exit e = eamos_test::wait_exit(run);
  kill(vehicle.pid, SIGTERM);
  eamos_test::wait_exit(vehicle);
  fs::remove_all(dir);
  EXPECT_TRUE(e.exited && e.status == 0) << run.seen;
  EXPECT_NE(run.seen.find("mission completed"), std::string::npos) << run.seen;
  EXPECT_GT(attacker.sent(), 20u);
  EXPECT_EQ(attacker.received(), 0u) << run.seen;
  // Counted and logged: at the first one, and in all at the end.
  EXPECT_NE(run.seen.find("datagram(s) from other addresses than system 1's"), std::string::npos) << run.seen;
  std::smatch total;
  ASSERT_TRUE(std::regex_search(run.seen, total, std::regex(R"((\d+) datagram\(s\) from other addresses than the vehicle's were ignored in all)")))
      << run.seen;
  EXPECT_EQ(std::stoull(total[1]), attacker.sent()) << run.seen;
  std::cout << "attacker sent " << attacker.sent() << " datagrams, received " << attacker.received() << "\n";
}

}  // namespace
