// What the adapter and the simulated vehicle really send each other during a short flight,
// captured on the wire by a UDP relay (udp_tap.h) and decoded by node-mavlink, an independent
// implementation (tests/mavlink/node/): every frame must pass its CRC check and decode to the
// values our own parser reads from the same bytes.
#include <gtest/gtest.h>

#include <set>

#include "mavlink/frame.h"
#include "mavlink/messages.h"
#include "mavlink_adapter/adapter.h"
#include "node_mavlink.h"
#include "udp_tap.h"
#include "vehicle_thread.h"

namespace eamos::mavlink_adapter {
namespace {

constexpr double kSpeed = 4.0;
constexpr uint16_t kVehiclePort = 25391;  // the tap, where the vehicle sends
constexpr uint16_t kAdapterPort = 25392;  // the adapter, where the tap forwards

/// The adapter's drone on a real-time loop, as in flight_test.cpp.
struct Flight {
  mid::EventLoop loop{{mid::ClockMode::real_time, kSpeed}};
  mid::AdapterRegistry registry;
  mid::CreateResult created;

  explicit Flight(uint16_t port) {
    MavlinkOptions options;
    options.real_time = true;
    options.speed = kSpeed;
    register_adapter(registry, options);
    fleet::DroneSettings s;
    s.name = "Drone1";
    s.adapter = "mavlink";
    s.connection = "udp://127.0.0.1:" + std::to_string(port);
    s.sysid = 1;
    created = registry.create("mavlink", s, fleet::generic_multirotor("Quad"), loop);
  }

  mid::ActionEnd fly(const std::string& name, std::vector<double> args = {}) {
    std::optional<mid::ActionEnd> end;
    created.drone->start({name, std::move(args)}, [&](const mid::ActionEnd& e) {
      end = e;
      loop.stop();
    });
    loop.run_until(loop.now() + 60);
    return end.value_or(mid::ActionEnd{mid::Outcome::failed, "test: no end within 60 s"});
  }
};

/// Decodes `bytes` with both implementations and expects them to agree frame by frame.
/// Returns the message ids seen.
std::set<uint32_t> expect_both_decode_alike(const std::vector<uint8_t>& bytes,
                                            const std::string& who) {
  std::set<uint32_t> ids;
  mavlink::test::ScratchDir dir;
  mavlink::test::write_file(dir.file(who + ".bin"), bytes);
  mavlink::test::NodeRun run =
      mavlink::test::run_node_mavlink("decode '" + dir.file(who + ".bin") + "'");
  EXPECT_EQ(run.exit_code, 0) << run.other_output;
  EXPECT_EQ(run.summary()["crc_errors"], 0) << who << ": node-mavlink rejected some checksums";
  EXPECT_EQ(run.summary()["unknown"], 0) << who << ": ids node-mavlink does not know";

  mavlink::Parser parser;
  std::vector<mavlink::Frame> ours = parser.feed(bytes);
  EXPECT_EQ(parser.stats().bad_crc + parser.stats().unknown_id + parser.stats().skipped_bytes, 0u)
      << who << ": our own parser found something wrong";
  std::vector<nlohmann::json> theirs = run.frames();
  EXPECT_EQ(theirs.size(), ours.size()) << who << ": frames decoded by node-mavlink vs by us";
  for (size_t i = 0; i < std::min(ours.size(), theirs.size()); ++i) {
    const mavlink::Frame& f = ours[i];
    std::string where = who + " frame " + std::to_string(i);
    EXPECT_EQ(theirs[i]["msgid"], f.message.id) << where;
    if (theirs[i]["msgid"] != f.message.id) break;  // out of step: the rest would only repeat it
    EXPECT_EQ(theirs[i]["seq"], f.seq) << where;
    EXPECT_EQ(theirs[i]["sysid"], f.sysid) << where;
    EXPECT_EQ(theirs[i]["compid"], f.compid) << where;
    EXPECT_EQ(theirs[i]["len"], f.wire_length) << where;
    mavlink::test::expect_same_fields(*mavlink::find_message(f.message.id), f.message,
                                      theirs[i]["fields"], where);
    ids.insert(f.message.id);
  }
  return ids;
}

TEST(NodeMavlinkCapture, NodeMavlinkDecodesAFlightsTrafficBothWaysWithoutCrcErrors) {
  ASSERT_EQ(mavlink::test::node_mavlink_missing(), "");
  test::UdpTap tap(kVehiclePort, kAdapterPort);
  {
    test::VehicleThread vehicle(kVehiclePort, 1, kSpeed);
    Flight f(kAdapterPort);
    ASSERT_TRUE(f.created.drone) << f.created.message;
    for (auto [action, args] : std::vector<std::pair<std::string, std::vector<double>>>{
             {"Arm", {}}, {"Takeoff", {2}}, {"FlyTo", {2, 1, 3}}, {"Land", {}}}) {
      mid::ActionEnd e = f.fly(action, args);
      ASSERT_EQ(e.outcome, mid::Outcome::succeeded) << action << ": " << e.reason;
    }
  }
  tap.stop();

  namespace msg = mavlink::msg;
  std::set<uint32_t> sent = expect_both_decode_alike(tap.from_adapter(), "adapter");
  for (uint32_t id : {msg::HEARTBEAT, msg::COMMAND_LONG, msg::SET_POSITION_TARGET_LOCAL_NED})
    EXPECT_TRUE(sent.contains(id)) << "the adapter never sent message " << id;
  std::set<uint32_t> received = expect_both_decode_alike(tap.from_vehicle(), "vehicle");
  for (uint32_t id : {msg::HEARTBEAT, msg::COMMAND_ACK, msg::LOCAL_POSITION_NED,
                      msg::GLOBAL_POSITION_INT, msg::EXTENDED_SYS_STATE, msg::SYS_STATUS,
                      msg::BATTERY_STATUS})
    EXPECT_TRUE(received.contains(id)) << "the vehicle never sent message " << id;
}

}  // namespace
}  // namespace eamos::mavlink_adapter
