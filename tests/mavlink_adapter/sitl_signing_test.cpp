// MAVLink 2 signing against real ArduCopter firmware: `eamos run` gives
// the SITL vehicle its key (SETUP_SIGNING) and flies a short mission signed; then a ground
// station of the test on another of the vehicle's ports sends commands unsigned, signed
// with a wrong key and replayed, and the vehicle ignores them: no COMMAND_ACK, no change of
// mode or arming state. The same command signed with the right key is obeyed, so the probe's frames do reach
// the vehicle. ArduPilot accepts unsigned frames on its first serial port (SERIAL0, TCP 5760 +
// 10 n: "assumed to be a secure channel, USB") whatever the key; every other port (SERIAL1,
// 5762, which eamos uses here, and SERIAL2, 5763, the probe's) enforces it. Skipped without
// EAMOS_ARDUPILOT_SITL.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "mavlink/enums.h"
#include "mavlink/link.h"
#include "mavlink/payloads.h"
#include "mavlink/signing.h"
#include "support/run_eamos.h"
#include "support/sitl.h"

namespace {

namespace fs = std::filesystem;
namespace ml = eamos::mavlink;
using eamos_test::Autopilot;
using eamos_test::SitlFleet;

constexpr double kSpeed = 5;
const char* kKey = "5a17c0ffee0ddba11deadbeef0123456789abcdef0123456789abcdef0fedcba";
const char* kWrongKey = "00112233445566778899aabbccddeeff00112233445566778899aabbccddeeff";

// ArduCopter's flight modes (custom_mode, DO_SET_MODE param2).
constexpr uint32_t kStabilize = 0, kGuided = 4, kLand = 9;

/// A ground station of the test on one of the vehicle's ports: it reads the vehicle's signed
/// frames with the right key and sends whatever the test gives it.
class Probe {
 public:
  Probe(const std::string& url, uint8_t vehicle) : vehicle_(vehicle) {
    std::string error;
    auto key = ml::parse_signing_key(kKey, error);
    auto opened = ml::Link::open(*eamos::fleet::parse_link_url(url).endpoint, [this](ml::Frame f) { on_frame(f); }, 0.2, key, false);
    link_ = std::move(opened.link);
    error_ = opened.error;
  }
  bool open() const { return link_ != nullptr; }
  const std::string& error() const { return error_; }
  /// Sends `m` through `encoder`; returns the bytes sent (to replay them).
  std::vector<uint8_t> send(ml::Encoder& encoder, const ml::Message& m) {
    std::vector<uint8_t> bytes = encoder.encode(m);
    link_->send(bytes);
    return bytes;
  }
  void send_bytes(const std::vector<uint8_t>& bytes) { link_->send(bytes); }
  /// Waits (wall time, bounded) until `done` holds over what the vehicle sent; false on timeout.
  bool wait(const std::function<bool()>& done, double timeout_s = 30) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, std::chrono::duration<double>(timeout_s), done);
  }
  // Read under wait()'s lock, or after it.
  std::vector<ml::CommandAck> acks;
  std::optional<ml::Heartbeat> heartbeat;
  int heartbeats = 0;

 private:
  void on_frame(const ml::Frame& f) {
    if (f.sysid != vehicle_ || f.compid != 1) return;
    std::lock_guard lock(mutex_);
    if (auto hb = ml::unpack_heartbeat(f.message)) {
      heartbeat = hb;
      ++heartbeats;
    }
    if (auto ack = ml::unpack_command_ack(f.message)) acks.push_back(*ack);
    changed_.notify_all();
  }
  uint8_t vehicle_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::unique_ptr<ml::Link> link_;
  std::string error_;
};

ml::CommandLong command(uint8_t vehicle, uint16_t id, std::array<float, 7> param) {
  ml::CommandLong c;
  c.target_system = vehicle;
  c.target_component = 1;
  c.command = id;
  c.param = param;
  return c;
}

ml::Encoder signed_encoder(const char* key_hex, uint8_t link_id) {
  std::string error;
  ml::Encoder e{245, 190, 0};
  e.signer.emplace(*ml::parse_signing_key(key_hex, error), link_id);
  return e;
}

int acks_of(const std::vector<ml::CommandAck>& acks, uint16_t id) {
  int n = 0;
  for (const auto& a : acks) n += a.command == id;
  return n;
}
bool acked(const std::vector<ml::CommandAck>& acks, uint16_t id) { return acks_of(acks, id) > 0; }

TEST(SitlSigning, ArduCopterWithTheKeyFliesSignedAndIgnoresUnsignedWronglySignedAndReplayedCommands) {
  if (SitlFleet::binary(Autopilot::ardupilot).empty()) GTEST_SKIP() << SitlFleet::skip_message(Autopilot::ardupilot);
  fs::path dir = fs::temp_directory_path() / ("eamos-sitl-signing-" + std::to_string(getpid()));
  fs::create_directories(dir);
  SitlFleet sitl({Autopilot::ardupilot, {{0, 0}}, kSpeed});
  std::string error;
  ASSERT_TRUE(sitl.start(error) && sitl.wait_ready(120, error)) << error;
  const int n = sitl.sysid(0) - 1;  // the instance number: ports are 5760 + 10 n + serial
  const auto vehicle = static_cast<uint8_t>(sitl.sysid(0));
  std::ofstream(dir / "fleet.yaml") << "types:\n  Quad: {adapter: mavlink}\ndrones:\n  Drone1: {adapter: mavlink, "
                                    << "connection: \"tcp://127.0.0.1:" << 5762 + 10 * n << "\", sysid: "
                                    << int(vehicle) << ", home: [0, 0, 0], signing: {key: \"" << kKey
                                    << "\", setup: true}}\n";
  eamos_test::Output r = eamos_test::run_eamos("run " + std::string(EAMOS_SOURCE_DIR) +
                                               "/tests/mavlink_adapter/missions/up_and_down.eamos --fleet " +
                                               (dir / "fleet.yaml").string() + " --speed 5");
  ASSERT_EQ(r.status, 0) << r.out << sitl.log_tail(0);
  EXPECT_NE(r.out.find("took the signing key"), std::string::npos) << r.out;

  // The vehicle has landed (LAND mode), disarmed, and holds the key. A probe on SERIAL2.
  Probe probe("tcp://127.0.0.1:" + std::to_string(5763 + 10 * n), vehicle);
  ASSERT_TRUE(probe.open()) << probe.error();
  ASSERT_TRUE(probe.wait([&] { return probe.heartbeat.has_value(); })) << "no signed HEARTBEAT on SERIAL2";
  EXPECT_EQ(probe.heartbeat->custom_mode, kLand);

  // Unsigned: arm. Wrong key: switch to GUIDED. Then, with the right key, a command that
  // changes nothing (a HEARTBEAT's interval): the vehicle handles a port's frames in order,
  // so when its ACK is back the two before it were ignored, not merely slow.
  ml::Encoder unsigned_encoder{245, 190, 0};
  ml::Encoder wrong = signed_encoder(kWrongKey, 7);
  ml::Encoder right = signed_encoder(kKey, 8);
  probe.send(unsigned_encoder, ml::pack(command(vehicle, ml::cmd::COMPONENT_ARM_DISARM, {1, 0, 0, 0, 0, 0, 0})));
  probe.send(wrong, ml::pack(command(vehicle, ml::cmd::DO_SET_MODE, {1, kGuided, 0, 0, 0, 0, 0})));
  probe.send(right, ml::pack(command(vehicle, ml::cmd::SET_MESSAGE_INTERVAL, {0, 1000000, 0, 0, 0, 0, 0})));
  ASSERT_TRUE(probe.wait([&] { return acked(probe.acks, ml::cmd::SET_MESSAGE_INTERVAL); }))
      << "the correctly signed command got no ACK: the probe does not reach the vehicle";
  EXPECT_FALSE(acked(probe.acks, ml::cmd::COMPONENT_ARM_DISARM)) << "the unsigned ARM was answered";
  EXPECT_FALSE(acked(probe.acks, ml::cmd::DO_SET_MODE)) << "the wrongly signed DO_SET_MODE was answered";
  // The vehicle's own state, from its next HEARTBEAT: still disarmed in LAND.
  int seen = probe.heartbeats;
  ASSERT_TRUE(probe.wait([&] { return probe.heartbeats > seen; }));
  EXPECT_EQ(probe.heartbeat->custom_mode, kLand);
  EXPECT_EQ(probe.heartbeat->base_mode & ml::mode_flag::SAFETY_ARMED, 0);

  // The same mode switch signed with the right key is obeyed: refusing was the key's doing.
  std::vector<uint8_t> to_guided =
      probe.send(right, ml::pack(command(vehicle, ml::cmd::DO_SET_MODE, {1, kGuided, 0, 0, 0, 0, 0})));
  ASSERT_TRUE(probe.wait([&] { return acked(probe.acks, ml::cmd::DO_SET_MODE); }));
  ASSERT_TRUE(probe.wait([&] { return probe.heartbeat->custom_mode == kGuided; }));

  // A replay: back to STABILIZE, then that correctly signed GUIDED frame again, byte for byte
  // (its timestamp is no longer newer than its stream's last), then a fresh marker.
  probe.send(right, ml::pack(command(vehicle, ml::cmd::DO_SET_MODE, {1, kStabilize, 0, 0, 0, 0, 0})));
  ASSERT_TRUE(probe.wait([&] { return probe.heartbeat->custom_mode == kStabilize; }));
  probe.send_bytes(to_guided);
  probe.send(right, ml::pack(command(vehicle, ml::cmd::SET_MESSAGE_INTERVAL, {0, 1000000, 0, 0, 0, 0, 0})));
  ASSERT_TRUE(probe.wait([&] { return acks_of(probe.acks, ml::cmd::SET_MESSAGE_INTERVAL) == 2; }));
  EXPECT_EQ(acks_of(probe.acks, ml::cmd::DO_SET_MODE), 2) << "the replayed DO_SET_MODE was answered";
  seen = probe.heartbeats;
  ASSERT_TRUE(probe.wait([&] { return probe.heartbeats > seen; }));
  EXPECT_EQ(probe.heartbeat->custom_mode, kStabilize) << "the replayed DO_SET_MODE was obeyed";
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
