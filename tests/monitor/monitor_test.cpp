// `eamos monitor` and `--monitor` with bad input, through the real process: a trace is
// untrusted, so every bad line is reported as file:line: error, all at once, exit 1.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "monitor/live_sink.h"
#include "monitor/server.h"
#include "monitor/trace_file.h"
#include "raw_client.h"
#include "support/eamos_process.h"
#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;

std::string write_temp(const std::string& name, const std::string& text) {
  fs::path p = fs::temp_directory_path() / (std::to_string(getpid()) + "-" + name);
  std::ofstream(p) << text;
  return p.string();
}

// Telemetry of `fleet_size` drones at 5 Hz for 3 s, one landing at 3.2 s and an action's
// start: how many events the live page is sent.
std::size_t live_events_of(std::size_t fleet_size) {
  eamos::monitor::MonitorServer server;
  std::vector<std::string> fleet;
  for (std::size_t d = 0; d < fleet_size; ++d) fleet.push_back("D" + std::to_string(d));
  eamos::monitor::LiveSink sink(server, fleet);
  auto sample = [&](double t, bool landed) {
    eamos::dex::TraceEvent e;
    e.t = t;
    e.event = "telemetry";
    e.drone = "D1";
    e.state = eamos::mid::DroneState{};
    e.state->armed = true;
    e.state->landed = landed;
    sink.record(e);
  };
  for (int k = 0; k <= 15; ++k) sample(k * 0.2, false);
  sample(3.2, true);
  eamos::dex::TraceEvent start, message;
  start.t = message.t = 3.2;
  start.event = "start";
  start.drone = "D1";
  sink.record(start);
  message.event = "message";
  message.kind = "trigger";
  message.from = 0;
  message.to = 1;
  sink.record(message);
  return server.event_count();
}

TEST(MonitorLive, AThousandDroneFleetsPageGetsEachDronesTelemetryOnceASecondAndNoMessages) {
  // 0, 1, 2 and 3 s, the landing and the start; a small fleet's page gets every sample and the message.
  EXPECT_EQ(live_events_of(1000), 6u);
  EXPECT_EQ(live_events_of(61), 6u);
  EXPECT_EQ(live_events_of(60), 19u);
  EXPECT_EQ(live_events_of(20), 19u);
  eamos::monitor::MonitorServer server;
  EXPECT_FALSE(eamos::monitor::LiveSink(server, std::vector<std::string>(61, "D")).takes_messages())
      << "the runner then builds none";
  EXPECT_TRUE(eamos::monitor::LiveSink(server, std::vector<std::string>(60, "D")).takes_messages());
}

TEST(MonitorTrace, EveryBadLineIsReportedWithItsLineNumber) {
  std::string path = write_temp("bad.jsonl",
                                "{\"t\":0,\"drone\":\"Drone1\",\"event\":\"start\",\"name\":\"Arm\",\"line\":3}\n"
                                "not json\n"
                                "{\"t\":\"soon\",\"event\":\"end\"}\n"
                                "[1,2]\n"
                                "{\"t\":1,\"event\":\"end\",\"line\":-4}\n");
  auto r = eamos_test::run_eamos("monitor " + path + " --port 0");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find(path + ":2: error: not valid JSON"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(path + ":3: error: \"t\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(path + ":4: error: a trace line must be a JSON object"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(path + ":5: error: \"line\" must be a whole number"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(":1: error"), std::string::npos) << r.out;
  fs::remove(path);
}

TEST(MonitorTrace, DeepNestingAndBinaryAreErrorsNotCrashes) {
  std::string nasty = std::string(200000, '[') + "\n" + std::string("\xff\xfe\x00garbage\n", 12) +
                      "{\"t\":1,\"event\":\"start\",\"drone\":\"\\ud800\"}\n";
  std::istringstream in(nasty);
  eamos::monitor::LoadedTrace t = eamos::monitor::read_trace("x.jsonl", in);
  EXPECT_EQ(t.errors.size(), 3u);
  EXPECT_TRUE(t.events.empty());
}

// A valid JSON line nested 100,000 deep in a field nobody reads: refused by its depth
// before it is parsed, as any bad line is, instead of overflowing the stack.
TEST(MonitorTrace, AValueNestedTooDeeplyIsAnErrorOfItsLineNotACrash) {
  std::string deep = std::string(100000, '[') + "1" + std::string(100000, ']');
  std::string path = write_temp("deep.jsonl", "{\"t\":0,\"drone\":\"D\",\"event\":\"start\",\"name\":\"Arm\"}\n"
                                              "{\"t\":1,\"event\":\"start\",\"future\":" + deep + "}\n");
  auto r = eamos_test::run_eamos("monitor " + path + " --port 0");
  EXPECT_EQ(r.status, 1) << r.out.substr(0, 300);
  EXPECT_NE(r.out.find(path + ":2: error: nested more than 64 levels deep"), std::string::npos) << r.out.substr(0, 300);
  EXPECT_EQ(r.out.find(":1: error"), std::string::npos) << r.out.substr(0, 300);
  fs::remove(path);
}

/// A file of one line of `bytes` 'a's and then a valid event, made as it is read: the test
/// itself never holds the long line.
class OneLongLine : public std::streambuf {
 public:
  explicit OneLongLine(std::size_t bytes) : left_(bytes) {}

 protected:
  int_type underflow() override {
    if (left_ > 0) {
      std::size_t n = std::min(left_, sizeof chunk_);
      std::fill_n(chunk_, n, 'a');
      left_ -= n;
      setg(chunk_, chunk_, chunk_ + n);
    } else if (!tail_done_) {
      tail_done_ = true;
      std::size_t n = tail_.copy(chunk_, sizeof chunk_);
      setg(chunk_, chunk_, chunk_ + n);
    } else {
      return traits_type::eof();
    }
    return traits_type::to_int_type(*gptr());
  }

 private:
  std::size_t left_;
  bool tail_done_ = false;
  std::string tail_ = "\n{\"t\":1,\"event\":\"start\",\"drone\":\"D\"}\n";
  char chunk_[1 << 16];
};

long peak_rss_kb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

// A corrupt trace of one line of hundreds of megabytes: an error at its line, read past with
// at most the line limit (64 MiB) held, and the lines after it still replayed.
TEST(MonitorTrace, AnEndlessLineIsAnErrorReadPastWithoutHoldingIt) {
  OneLongLine source(300u << 20);
  std::istream in(&source);
  long before = peak_rss_kb();
  eamos::monitor::LoadedTrace t = eamos::monitor::read_trace("x.jsonl", in);
  long grew_mb = (peak_rss_kb() - before) / 1024;
  ASSERT_EQ(t.errors.size(), 1u);
  EXPECT_NE(t.errors[0].find("x.jsonl:1: error: line longer than 64 MiB"), std::string::npos) << t.errors[0];
  ASSERT_EQ(t.events.size(), 1u);
  EXPECT_NE(t.events[0].find("\"start\""), std::string::npos);
#ifndef EAMOS_SANITIZED  // a sanitizer's quarantine keeps every freed block of the growing line
  EXPECT_LT(grew_mb, 200) << "the 300 MiB line was held";
#else
  (void)grew_mb;
#endif
}

TEST(MonitorTrace, ACutOffLastLineIsAWarningNotAnError) {
  std::istringstream in("{\"t\":0,\"event\":\"start\",\"drone\":\"D\"}\n{\"t\":1,\"ev");
  eamos::monitor::LoadedTrace t = eamos::monitor::read_trace("x.jsonl", in);
  EXPECT_TRUE(t.errors.empty());
  ASSERT_EQ(t.warnings.size(), 1u);
  EXPECT_NE(t.warnings[0].find("x.jsonl:2: warning: the last line is cut off"), std::string::npos);
  EXPECT_EQ(t.events.size(), 1u);
}

TEST(MonitorTrace, AHeaderOfAnotherSchemaVersionIsRefused) {
  std::istringstream in("{\"t\":0,\"event\":\"header\",\"schema\":\"eamos-trace\",\"version\":7}\n");
  eamos::monitor::LoadedTrace t = eamos::monitor::read_trace("x.jsonl", in);
  ASSERT_EQ(t.errors.size(), 1u);
  EXPECT_NE(t.errors[0].find("version 7 is not supported"), std::string::npos) << t.errors[0];
}

// docs/trace.md: "heading" is null when the vehicle reports none (a MAVLink vehicle may not);
// such a trace was refused line by line.
TEST(MonitorTrace, TelemetryWithoutAHeadingIsReplayed) {
  std::istringstream in("{\"t\":0.2,\"event\":\"telemetry\",\"drone\":\"D\",\"x\":1,\"y\":2,\"z\":3,"
                        "\"heading\":null,\"armed\":true,\"landed\":false,\"battery\":99,\"mode\":\"\"}\n"
                        "{\"t\":0.4,\"event\":\"telemetry\",\"drone\":\"D\",\"heading\":\"north\"}\n");
  eamos::monitor::LoadedTrace t = eamos::monitor::read_trace("x.jsonl", in);
  EXPECT_EQ(t.events.size(), 1u);
  ASSERT_EQ(t.errors.size(), 1u);
  EXPECT_NE(t.errors[0].find("x.jsonl:2: error: \"heading\" must be a number or null"), std::string::npos) << t.errors[0];
}

TEST(MonitorTrace, UnknownEventsAndFieldsAreKept) {
  std::istringstream in("{\"t\":0.5,\"event\":\"something-new\",\"future\":{\"a\":1}}\n");
  eamos::monitor::LoadedTrace t = eamos::monitor::read_trace("x.jsonl", in);
  EXPECT_TRUE(t.errors.empty());
  ASSERT_EQ(t.events.size(), 1u);
  EXPECT_NE(t.events[0].find("something-new"), std::string::npos);
}

TEST(MonitorEndpoint, HostAndPortAreChecked) {
  eamos::monitor::Endpoint e;
  std::string error;
  EXPECT_TRUE(eamos::monitor::parse_endpoint("8080", e, error));
  EXPECT_EQ(e.host, "127.0.0.1");
  EXPECT_EQ(e.port, 8080);
  EXPECT_TRUE(eamos::monitor::parse_endpoint("0.0.0.0:9000", e, error));
  EXPECT_EQ(e.host, "0.0.0.0");
  EXPECT_FALSE(eamos::monitor::parse_endpoint("70000", e, error));
  EXPECT_NE(error.find("is not a port number"), std::string::npos);
  EXPECT_FALSE(eamos::monitor::parse_endpoint("host;rm:80", e, error));
  EXPECT_FALSE(eamos::monitor::parse_endpoint("", e, error));
}

// civetweb read each of the four numbers modulo 256: 999.1.1.1 listened on 231.1.1.1.
TEST(MonitorEndpoint, OnlyRealIpAddressesAreAccepted) {
  eamos::monitor::Endpoint e;
  std::string error;
  for (const char* bad : {"999.1.1.1:8080", "256.0.0.1:80", "1.2.3:80", "1.2.3.4.5:80", "example.com:80", "::g:80",
                          "[127.0.0.1]x:80"}) {
    error.clear();
    EXPECT_FALSE(eamos::monitor::parse_endpoint(bad, e, error)) << bad;
    EXPECT_NE(error.find("is not an IP address"), std::string::npos) << bad << ": " << error;
  }
  EXPECT_TRUE(eamos::monitor::parse_endpoint("localhost:80", e, error));
  EXPECT_EQ(e.host, "127.0.0.1");
  EXPECT_TRUE(eamos::monitor::parse_endpoint("[::1]:8080", e, error));
  EXPECT_EQ(e.host, "::1");
  EXPECT_EQ(e.port, 8080);
  EXPECT_TRUE(eamos::monitor::parse_endpoint("10.1.2.3:0", e, error));
  EXPECT_EQ(e.host, "10.1.2.3");
}

TEST(MonitorEndpoint, AnInvalidHostIsRefusedBeforeAnythingIsServed) {
  std::string trace = write_temp("host.jsonl", "{\"t\":0,\"event\":\"start\",\"drone\":\"Drone1\"}\n");
  auto r = eamos_test::run_eamos("monitor " + trace + " --host 999.1.1.1 --port 0");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("error: --host '999.1.1.1' is not an IP address"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("replaying"), std::string::npos) << r.out;
  auto run = eamos_test::run_eamos("run examples/listing2.eamos -q --monitor 999.1.1.1:0");
  EXPECT_EQ(run.status, 1);
  EXPECT_NE(run.out.find("error: --monitor '999.1.1.1' is not an IP address"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("monitor at"), std::string::npos) << run.out;
  fs::remove(trace);
}

// One raw HTTP/1.1 request to 127.0.0.1:port; the whole answer ("" when none).
std::string http(int port, const std::string& request) {
  int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string answer;
  if (connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0) {
    (void)!write(fd, request.data(), request.size());
    shutdown(fd, SHUT_WR);
    char buf[4096];
    ssize_t n;
    while ((n = read(fd, buf, sizeof buf)) > 0) answer.append(buf, static_cast<std::size_t>(n));
  }
  close(fd);
  return answer;
}

int port_of(const std::string& seen) {
  std::size_t at = seen.find("http://127.0.0.1:");
  return at == std::string::npos ? -1 : std::atoi(seen.c_str() + at + 17);
}

std::string get(int port, const std::string& path, const std::string& host) {
  return http(port, "GET " + path + " HTTP/1.1\r\nHost: " + host + "\r\nConnection: close\r\n\r\n");
}

TEST(MonitorServer, ServesOnlyThePageAndRefusesEverythingThatWouldChangeSomething) {
  std::string trace = write_temp("ok.jsonl", "{\"t\":0,\"drone\":\"Drone1\",\"event\":\"start\",\"name\":\"Arm\",\"line\":3}\n");
  auto p = eamos_test::start_eamos({"monitor", trace, "--port", "0"});
  ASSERT_TRUE(eamos_test::read_until(p, "replaying")) << p.seen;
  int port = port_of(p.seen);
  ASSERT_GT(port, 0) << p.seen;
  std::string self = "127.0.0.1:" + std::to_string(port);
  std::string page = get(port, "/", self);
  EXPECT_EQ(page.rfind("HTTP/1.1 200", 0), 0u) << page;
  EXPECT_NE(page.find("<title>eamos monitor</title>"), std::string::npos);
  EXPECT_NE(page.find("Content-Security-Policy: default-src 'self'"), std::string::npos);
  EXPECT_EQ(get(port, "/monitor.js", self).rfind("HTTP/1.1 200", 0), 0u);
  EXPECT_EQ(http(port, "POST / HTTP/1.1\r\nHost: " + self + "\r\nContent-Length: 2\r\n\r\n{}").rfind("HTTP/1.1 405", 0), 0u);
  EXPECT_EQ(http(port, "PUT /monitor.js HTTP/1.1\r\nHost: " + self + "\r\nContent-Length: 0\r\n\r\n").rfind("HTTP/1.1 405", 0), 0u);
  EXPECT_EQ(get(port, "/../../etc/passwd", self).find("root:"), std::string::npos);
  EXPECT_EQ(get(port, "/nothing", self).rfind("HTTP/1.1 404", 0), 0u);
  // DNS rebinding: another name for this address is not served.
  EXPECT_EQ(get(port, "/", "evil.example:" + std::to_string(port)).rfind("HTTP/1.1 403", 0), 0u);
  // A WebSocket from another site's page is refused.
  std::string upgrade = http(port, "GET /ws HTTP/1.1\r\nHost: " + self + "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                                   "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
                                   "Origin: http://evil.example\r\n\r\n");
  EXPECT_EQ(upgrade.find("101 Switching Protocols"), std::string::npos) << upgrade;
  kill(p.pid, SIGTERM);
  eamos_test::Exit e = eamos_test::wait_exit(p);
  EXPECT_TRUE(e.exited);
  EXPECT_EQ(e.status, 0);
  fs::remove(trace);
}

// How many events a message of the server carries (each is a JSON object with an "event").
std::size_t events_in(const std::string& message) {
  std::size_t n = 0;
  for (std::size_t at = message.find("\"event\":"); at != std::string::npos; at = message.find("\"event\":", at + 1)) ++n;
  return n;
}

// The events that come while a page's last message is being written and read go out together
// as the next one: a browser handles each message as a task of its own, and a thousand-drone
// run, one message per event, kept a page's main thread busy with messages alone.
TEST(MonitorServer, EventsThatComeTogetherReachAPageInOneMessage) {
  eamos::monitor::ServerLimits limits;
  limits.batch_interval_s = 1.0;  // far longer than appending 200 events takes
  eamos::monitor::MonitorServer server(limits);
  server.set_mission("{}");
  eamos::monitor::Endpoint at;
  at.port = 0;
  std::string error;
  ASSERT_TRUE(server.start(at, error)) << error;
  int port = port_of(server.url());
  eamos_test::RawClient page;
  eamos_test::Deadline until = eamos_test::after(20);
  ASSERT_TRUE(page.connect_to(port) && page.websocket_handshake(port, until) && page.send_text("hello"));
  std::string text;
  ASSERT_TRUE(page.next_text(text, until));
  ASSERT_NE(text.find("\"type\":\"mission\""), std::string::npos) << text;
  auto event = [](int i) { return "{\"t\":" + std::to_string(i) + ",\"event\":\"start\",\"drone\":\"D1\",\"line\":1}"; };
  server.append(event(0), 1);
  ASSERT_TRUE(page.next_text(text, until));
  EXPECT_EQ(events_in(text), 1u) << text;
  // A run that emits an event every 2 ms for 0.4 s (the pace is the test's input, not a wait).
  std::thread run([&] {
    auto next = std::chrono::steady_clock::now();
    for (int i = 1; i <= 200; ++i) {
      next += std::chrono::milliseconds(2);
      std::this_thread::sleep_until(next);
      server.append(event(i), 1);
    }
  });
  std::size_t messages = 0, events = 0;
  while (events < 200 && page.next_text(text, until)) ++messages, events += events_in(text);
  run.join();
  EXPECT_EQ(events, 200u);
  EXPECT_LE(messages, 3u) << "the 200 events came in " << messages << " messages, not together";
  server.stop();
}

// The distributed run (one DEX process per drone over DDS) serves its ground's events the same way.
TEST(MonitorRun, ADistributedRunIsServedLiveAndStaysUpUntilStopped) {
  auto p = eamos_test::start_eamos({"run", "examples/listing2.eamos", "-q", "--distributed", "--insecure", "--speed", "4",
                                    "--domain", "201", "--monitor", "127.0.0.1:0"});
  ASSERT_TRUE(eamos_test::read_until(p, "monitor at")) << p.seen;
  int port = port_of(p.seen);
  ASSERT_GT(port, 0) << p.seen;
  EXPECT_EQ(get(port, "/", "127.0.0.1:" + std::to_string(port)).rfind("HTTP/1.1 200", 0), 0u);
  ASSERT_TRUE(eamos_test::read_until(p, "until Ctrl-C")) << p.seen;
  EXPECT_NE(p.seen.find("mission completed"), std::string::npos) << p.seen;
  kill(p.pid, SIGTERM);
  eamos_test::Exit e = eamos_test::wait_exit(p);
  EXPECT_TRUE(e.exited);
  EXPECT_EQ(e.status, 0) << p.seen;
}

TEST(MonitorRun, AFleetWithoutItsMissionIsAnError) {
  std::string trace = write_temp("fleet.jsonl", "{\"t\":0,\"event\":\"start\",\"drone\":\"Drone1\"}\n");
  auto r = eamos_test::run_eamos("monitor " + trace + " --fleet examples/listing2-right.yaml --port 0");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("--fleet needs --mission"), std::string::npos) << r.out;
  fs::remove(trace);
}

TEST(MonitorRun, ABadMonitorAddressStopsTheRunBeforeItFlies) {
  auto r = eamos_test::run_eamos("run examples/listing2.eamos -q --monitor 99999");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("error: --monitor '99999' is not a port number"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("Drone1"), std::string::npos) << r.out;
}

}  // namespace
