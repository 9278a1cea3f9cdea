// DdsNode's QoS where it matters: a reader that joins late still gets every trigger
// (transient-local, keep-all) and only the newest telemetry (keep-last 1 per drone).
// Two nodes in one process on loopback, each test on its own domain. Waits block on a
// condition variable with a generous bound; nothing sleeps.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <tuple>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include "transport/dds_node.h"

namespace eamos::transport {
namespace {

// Filled by the handlers on Cyclone's listener threads. Its mutex is never held while a node
// goes away: deleting a node waits for its listeners, which may be waiting for this mutex
// while Cyclone holds the reader's own lock (a deadlock ThreadSanitizer reported).
struct Received {
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<TriggerSample> triggers;
  std::vector<TelemetrySample> telemetry;
  std::vector<StatusSample> status;
  std::vector<std::tuple<std::string, int, std::uint64_t>> lost;

  bool wait(const std::function<bool()>& done) {
    std::unique_lock<std::mutex> lock(mutex);
    return cv.wait_for(lock, std::chrono::seconds(20), done);
  }
};

DdsHandlers record_into(Received& r) {
  DdsHandlers h;
  h.trigger = [&r](TriggerSample s) {
    std::lock_guard<std::mutex> lock(r.mutex);
    r.triggers.push_back(std::move(s));
    r.cv.notify_all();
  };
  h.telemetry = [&r](TelemetrySample s) {
    std::lock_guard<std::mutex> lock(r.mutex);
    r.telemetry.push_back(std::move(s));
    r.cv.notify_all();
  };
  h.status = [&r](StatusSample s) {
    std::lock_guard<std::mutex> lock(r.mutex);
    r.status.push_back(std::move(s));
    r.cv.notify_all();
  };
  h.lost = [&r](const std::string& hash, int drone, std::uint64_t nonce) {
    std::lock_guard<std::mutex> lock(r.mutex);
    r.lost.emplace_back(hash, drone, nonce);
    r.cv.notify_all();
  };
  return h;
}

TEST(DdsNode, LateReaderGetsTheNewestTriggersTheWriterKeepsInOrder) {
  // A reader matched after the writes gets what the writer's durable history holds: the
  // newest `durable_triggers` (the older ones were acknowledged by every reader matched
  // then), in the order written. A writer that kept them all grew with the mission.
  std::string error;
  DdsOptions options;
  options.domain = 41;
  options.durable_triggers = 100;
  Received ignored;
  auto writer = DdsNode::open(options, record_into(ignored), error);
  ASSERT_TRUE(writer) << error;
  for (int i = 1; i <= 500; ++i) {
    TriggerSample s;
    s.run_id = 1;
    s.to = 1;
    s.seq = static_cast<std::uint64_t>(i);
    s.message.mission_hash = "h";
    s.message.meg = i;
    ASSERT_TRUE(writer->write(s));
  }
  Received got;
  auto reader = DdsNode::open(options, record_into(got), error);
  ASSERT_TRUE(reader) << error;
  ASSERT_TRUE(got.wait([&] { return got.triggers.size() >= 100; })) << got.triggers.size();
  // One more, written now: it comes after the history, and nothing older than it came.
  TriggerSample last;
  last.run_id = 1;
  last.to = 1;
  last.seq = 501;
  last.message.mission_hash = "h";
  ASSERT_TRUE(writer->write(last));
  ASSERT_TRUE(got.wait([&] { return got.triggers.size() >= 101; })) << got.triggers.size();
  {
    std::lock_guard<std::mutex> lock(got.mutex);
    ASSERT_EQ(got.triggers.size(), 101u);
    for (int i = 0; i < 101; ++i) EXPECT_EQ(got.triggers[i].seq, static_cast<std::uint64_t>(401 + i));
  }
  reader.reset();
  writer.reset();
}

TEST(DdsNode, LateReaderGetsOnlyTheNewestTelemetryPerDrone) {
  std::string error;
  DdsOptions options;
  options.domain = 42;
  Received ignored;
  auto writer = DdsNode::open(options, record_into(ignored), error);
  ASSERT_TRUE(writer) << error;
  for (int drone = 0; drone < 2; ++drone)
    for (int i = 1; i <= 10; ++i) {
      TelemetrySample s;
      s.telemetry.mission_hash = "h";
      s.telemetry.from = drone;
      s.telemetry.state.x = i;
      ASSERT_TRUE(writer->write(s));
    }
  Received got;
  auto reader = DdsNode::open(options, record_into(got), error);
  ASSERT_TRUE(reader) << error;
  ASSERT_TRUE(got.wait([&] { return got.telemetry.size() >= 2; }));
  {
    std::lock_guard<std::mutex> lock(got.mutex);
    ASSERT_EQ(got.telemetry.size(), 2u);
    for (const TelemetrySample& s : got.telemetry) EXPECT_EQ(s.telemetry.state.x, 10);
  }
  reader.reset();
  writer.reset();
}

TEST(DdsNode, ReportsWhoseStatusWriterWentAway) {
  std::string error;
  DdsOptions options;
  options.domain = 43;
  Received watcher;
  auto observer = DdsNode::open(options, record_into(watcher), error);  // created first: owns the domain
  ASSERT_TRUE(observer) << error;
  Received ignored;
  auto drone = DdsNode::open(options, record_into(ignored), error);
  ASSERT_TRUE(drone) << error;
  StatusSample s;
  s.mission_hash = "h";
  s.drone = 2;
  s.nonce = 99;
  ASSERT_TRUE(drone->write(s));
  ASSERT_TRUE(watcher.wait([&] { return !watcher.status.empty(); }));
  drone.reset();  // the process goes away
  ASSERT_TRUE(watcher.wait([&] { return !watcher.lost.empty(); }));
  {
    std::lock_guard<std::mutex> lock(watcher.mutex);
    EXPECT_EQ(watcher.lost.front(), std::make_tuple(std::string("h"), 2, std::uint64_t{99}));
  }
  observer.reset();
}

// A handler runs on Cyclone's listener thread, called from C: an exception going up through
// Cyclone itself would hang this test (a DEX would stop hearing the others, or die). The one
// sample is dropped and the rest of the batch still arrives.
TEST(DdsNode, HandlerThatThrowsLosesOnlyItsSample) {
  std::string error;
  DdsOptions options;
  options.domain = 44;
  Received ignored;
  auto writer = DdsNode::open(options, record_into(ignored), error);
  ASSERT_TRUE(writer) << error;
  for (int i = 1; i <= 3; ++i) {
    TriggerSample s;
    s.run_id = 1;
    s.seq = static_cast<std::uint64_t>(i);
    s.message.mission_hash = "h";
    ASSERT_TRUE(writer->write(s));
  }
  Received got;
  DdsHandlers h = record_into(got);
  h.trigger = [&got](TriggerSample s) {
    if (s.seq == 2) throw std::out_of_range("bad sample");
    std::lock_guard<std::mutex> lock(got.mutex);
    got.triggers.push_back(std::move(s));
    got.cv.notify_all();
  };
  auto reader = DdsNode::open(options, std::move(h), error);
  ASSERT_TRUE(reader) << error;
  ASSERT_TRUE(got.wait([&] { return got.triggers.size() >= 2; })) << got.triggers.size();
  {
    std::lock_guard<std::mutex> lock(got.mutex);
    EXPECT_EQ(got.triggers[0].seq, 1u);
    EXPECT_EQ(got.triggers[1].seq, 3u);
  }
  reader.reset();
  writer.reset();
}

TEST(DdsNode, RejectsADomainIdOutOfRange) {
  std::string error;
  DdsOptions options;
  options.domain = 500;
  EXPECT_FALSE(DdsNode::open(options, {}, error));
  EXPECT_NE(error.find("out of range"), std::string::npos) << error;
}

TEST(DdsNode, RejectsAMissingConfigFile) {
  std::string error;
  DdsOptions options;
  options.config_file = "/nonexistent/cyclonedds.xml";
  EXPECT_FALSE(DdsNode::open(options, {}, error));
  EXPECT_NE(error.find("/nonexistent/cyclonedds.xml"), std::string::npos) << error;
}

TEST(DdsNode, DropsAndLogsASampleFromADroneOutsideTheFleetAndDeliversTheNext) {
  std::string error;
  DdsOptions options;
  options.domain = 44;
  Received ignored;
  auto writer = DdsNode::open(options, record_into(ignored), error);
  ASSERT_TRUE(writer) << error;
  Received got;
  std::vector<std::string> dropped;
  DdsHandlers h = record_into(got);
  h.limits.drones = 2;
  h.dropped = [&](const std::string& line) {
    std::lock_guard<std::mutex> lock(got.mutex);
    dropped.push_back(line);
    got.cv.notify_all();
  };
  auto reader = DdsNode::open(options, std::move(h), error);
  ASSERT_TRUE(reader) << error;
  // Triggers are reliable and kept in order: the bad one arrives before the good one.
  TriggerSample bad;
  bad.to = 1;
  bad.seq = 1;
  bad.message.mission_hash = "h";
  bad.message.from = 99;
  ASSERT_TRUE(writer->write(bad));
  TriggerSample good = bad;
  good.seq = 2;
  good.message.from = 0;
  ASSERT_TRUE(writer->write(good));
  ASSERT_TRUE(got.wait([&] { return !got.triggers.empty(); }));
  {
    std::lock_guard<std::mutex> lock(got.mutex);
    ASSERT_EQ(got.triggers.size(), 1u);
    EXPECT_EQ(got.triggers[0].seq, 2u);
    ASSERT_EQ(dropped.size(), 1u);
    EXPECT_EQ(dropped[0], "dropped a trigger sample: from 99 is not a drone of the mission (2 drones) (1 dropped so far)");
  }
  EXPECT_EQ(reader->dropped_count(), 1u);
  reader.reset();
  writer.reset();
}

TEST(DdsNode, DropsASampleWhoseSenderIsNotTheDroneWhosePartitionItsWriterIsIn) {
  // Drone1's participant (partition "eamos.h.0") writes a status claiming to be Drone2's:
  // with DDS Security that partition is Drone1's identity, so the claim is a lie.
  std::string error;
  DdsOptions options;
  options.domain = 159;
  options.mission_hash = "h";
  Received got;
  std::vector<std::string> dropped;
  DdsHandlers h = record_into(got);
  h.limits.drones = 3;
  h.dropped = [&](const std::string& line) {
    std::lock_guard<std::mutex> lock(got.mutex);
    dropped.push_back(line);
  };
  auto ground = DdsNode::open(options, std::move(h), error);  // the ground: first, owns the domain
  ASSERT_TRUE(ground) << error;
  options.self = 0;
  Received ignored;
  DdsHandlers dh = record_into(ignored);
  dh.limits.drones = 3;
  auto drone1 = DdsNode::open(options, std::move(dh), error);
  ASSERT_TRUE(drone1) << error;
  StatusSample forged;
  forged.mission_hash = "h";
  forged.drone = 1;
  forged.nonce = 7;
  ASSERT_TRUE(drone1->write(forged));
  StatusSample own = forged;
  own.drone = 0;  // another instance, after the forged one from the same writer
  ASSERT_TRUE(drone1->write(own));
  ASSERT_TRUE(got.wait([&] { return !got.status.empty(); }));
  {
    std::lock_guard<std::mutex> lock(got.mutex);
    ASSERT_EQ(got.status.size(), 1u);
    EXPECT_EQ(got.status[0].drone, 0);
    ASSERT_EQ(dropped.size(), 1u);
    EXPECT_EQ(dropped[0], "dropped a status sample: it says it is from drone 1 but was written by drone 0 (the "
                          "partition its writer is in) (1 dropped so far)");
  }
  drone1.reset();
  ground.reset();
}


// A member of Cyclone's discovery group on lo, at the port of `domain`'s participant
// announcements (DDSI: 7400 + 250 * domain). -1 when the host refuses.
int join_discovery_group_on_loopback(int domain) {
  int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  int one = 1;
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in at{};
  at.sin_family = AF_INET;
  at.sin_port = htons(static_cast<std::uint16_t>(7400 + 250 * domain));
  at.sin_addr.s_addr = htonl(INADDR_ANY);
  ip_mreq group{};
  inet_pton(AF_INET, "239.255.0.1", &group.imr_multiaddr);
  inet_pton(AF_INET, "127.0.0.1", &group.imr_interface);
  if (bind(fd, reinterpret_cast<sockaddr*>(&at), sizeof at) != 0 ||
      setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &group, sizeof group) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

// Sent once to the group rather than to a port per possible peer: what lets a hundred
// participants start on one host (docs/performance.md, "Many DEX processes on one host").
TEST(DdsNode, OnLoopbackAnnouncesItselfOnceToTheMulticastGroup) {
  const int domain = 45;
  int fd = join_discovery_group_on_loopback(domain);
  ASSERT_GE(fd, 0) << "cannot join 239.255.0.1 on lo: " << std::strerror(errno);
  std::string error;
  DdsOptions options;  // no interface, no file: the loopback configuration compiled in
  options.domain = domain;
  auto node = DdsNode::open(options, {}, error);
  ASSERT_TRUE(node) << error;
  pollfd p{fd, POLLIN, 0};
  // Cyclone announces a participant as it creates it; the bound only ends a failing test.
  ASSERT_EQ(poll(&p, 1, 20000), 1) << "no participant announcement on the multicast group";
  char datagram[2048];
  ssize_t n = recv(fd, datagram, sizeof datagram, 0);
  close(fd);
  ASSERT_GE(n, 20);
  EXPECT_EQ(std::string(datagram, 4), "RTPS");
}

// Cyclone's 100 ms heartbeats were most of a 50-drone start's messages (docs/performance.md);
// a small fleet keeps them, as its start would only be slower, and a user's file is untouched.
TEST(DdsNode, OnLoopbackAFleetOfMoreThanTwentyDronesGetsASlowerHeartbeat) {
  std::string xml, error;
  DdsOptions options;
  ASSERT_TRUE(dds_config(options, xml, error, kQuickHeartbeatFleet + 1)) << error;
  EXPECT_NE(xml.find(">500ms</HeartbeatInterval>"), std::string::npos) << xml;
  ASSERT_TRUE(dds_config(options, xml, error, kQuickHeartbeatFleet)) << error;
  EXPECT_EQ(xml.find("HeartbeatInterval"), std::string::npos) << xml;
  options.interface = "eth0";
  ASSERT_TRUE(dds_config(options, xml, error, 100)) << error;
  EXPECT_EQ(xml.find("HeartbeatInterval"), std::string::npos) << xml;
}

}  // namespace
}  // namespace eamos::transport
