// The monitor's server under browsers that misbehave, through the real `eamos` process: one
// that stops reading must not delay the others, and idle WebSockets and half-sent requests
// must leave room for a new page (docs/monitor.md, "Many browsers, slow ones"). Raw TCP
// clients (raw_client.h) play the browsers; every wait has a deadline.
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "monitor/raw_client.h"
#include "support/eamos_process.h"
#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;
using eamos_test::after;
using eamos_test::Deadline;
using eamos_test::RawClient;

double wall_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch()).count();
}

int port_of(const std::string& seen) {
  std::size_t at = seen.find("http://127.0.0.1:");
  return at == std::string::npos ? -1 : std::atoi(seen.c_str() + at + 17);
}

// The "type" of a message from the server; "" when it is not a JSON object.
std::string message_type(const std::string& text) {
  nlohmann::json m = nlohmann::json::parse(text, nullptr, false);
  return m.is_object() && m.contains("type") && m["type"].is_string() ? m["type"].get<std::string>() : "";
}

// A page's WebSocket: the handshake and its hello (a page says hello at once).
bool open_page(RawClient& page, int port, Deadline until) {
  return page.connect_to(port) && page.websocket_handshake(port, until) && page.send_text("hello");
}

// Live events as a page gets them: the lag of each from eamos emitting it to its arrival
// here. Events emitted before the page had its history are not counted (as the page does).
bool read_live_lags(RawClient& page, std::size_t count, Deadline until, std::vector<double>& lags) {
  double joined = 0;
  std::string text;
  while (lags.size() < count && page.next_text(text, until)) {
    if (message_type(text) != "events") continue;
    nlohmann::json m = nlohmann::json::parse(text);
    if (!m["emitted"].is_array()) continue;
    double now = wall_ms();
    if (joined == 0) joined = now;
    for (const auto& e : m["emitted"])
      if (e.is_number() && e.get<double>() >= joined) lags.push_back(now - e.get<double>());
  }
  return lags.size() >= count;
}

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[std::min(v.size() - 1, static_cast<std::size_t>(q * v.size()))];
}

// Two browsers that say hello and never read again: one over a slow link (the server's
// writes to it block within the mission), one with the usual buffers (it never answers a
// ping). A healthy page beside them gets every live event at once, a new page its mission.
void watch_with_stuck_browsers(int port) {
  RawClient healthy, stuck_small, stuck_idle;
  ASSERT_TRUE(open_page(healthy, port, after(10)));
  ASSERT_TRUE(open_page(stuck_idle, port, after(10)));
  ASSERT_TRUE(stuck_small.connect_to(port, true) && stuck_small.websocket_handshake(port, after(10)) &&
              stuck_small.send_text("hello"));
  std::vector<double> lags;
  EXPECT_TRUE(read_live_lags(healthy, 400, after(30), lags)) << lags.size() << " live events";
  double p95 = percentile(lags, 0.95), max = percentile(lags, 1.0);
  std::printf("info: %zu live events, lag p95 %.1f ms, max %.1f ms\n", lags.size(), p95, max);
  EXPECT_LT(p95, 250.0);
  EXPECT_LT(max, 1500.0);
  auto begin = std::chrono::steady_clock::now();
  RawClient late;
  std::string first;
  EXPECT_TRUE(open_page(late, port, after(5)) && late.next_text(first, after(5)));
  EXPECT_EQ(message_type(first), "mission");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count(), 2.0);
  // The server drops both stuck browsers: a write that makes no progress, a ping unanswered.
  EXPECT_TRUE(stuck_small.closed_by_server(after(20)));
  EXPECT_TRUE(stuck_idle.closed_by_server(after(20)));
}

// One browser that stops reading must not hold up the others (a server writing to all pages
// from one thread would: a healthy page's lag p95 18.5 s, a new page's handshake 36 s).
TEST(MonitorServerLoad, ABrowserThatStopsReadingDelaysNoOtherAndIsDropped) {
  fs::path dir = fs::temp_directory_path() / ("eamos-monitor-load-" + std::to_string(getpid()));
  fs::create_directories(dir);
  std::string mission = (dir / "fleet.eamos").string();
  ASSERT_EQ(eamos_test::run_eamos("gen-stress --drones 20 --nodes 120 -o " + mission).status, 0);
  auto run = eamos_test::start_eamos({"run", mission, "-q", "--realtime", "--monitor", "127.0.0.1:0"});
  ASSERT_TRUE(eamos_test::read_until(run, "monitor at")) << run.seen;
  int port = port_of(run.seen);
  ASSERT_GT(port, 0) << run.seen;
  std::thread log([&] { eamos_test::read_until(run, std::string(1, '\0')); });  // as a terminal would
  watch_with_stuck_browsers(port);
  kill(run.pid, SIGKILL);  // the simulated flight's landing is not what this test is about
  log.join();
  eamos_test::wait_exit(run);
  fs::remove_all(dir);
}

// The page's three files and its WebSocket to the end of the replay.
bool load_page(int port, Deadline until) {
  std::string host = "127.0.0.1:" + std::to_string(port);
  for (const char* path : {"/", "/monitor.js", "/monitor.css"}) {
    RawClient get;
    std::string answer;
    if (!get.connect_to(port) || !get.send_all(std::string("GET ") + path + " HTTP/1.1\r\nHost: " + host + "\r\n\r\n") ||
        !get.read_all(answer, until) || answer.rfind("HTTP/1.1 200", 0) != 0)
      return false;
  }
  RawClient page;
  if (!open_page(page, port, until)) return false;
  std::string text;
  while (page.next_text(text, until))
    if (message_type(text) == "finished") return true;
  return false;
}

// Idle WebSockets and half-sent requests must not lock everyone out.
TEST(MonitorServerLoad, FortyIdleWebSocketsAndFortyHalfSentRequestsLeaveRoomForANewPage) {
  fs::path dir = fs::temp_directory_path() / ("eamos-monitor-room-" + std::to_string(getpid()));
  fs::create_directories(dir);
  std::string trace = (dir / "listing2.jsonl").string();
  ASSERT_EQ(eamos_test::run_eamos("run examples/listing2.eamos -q --trace " + trace).status, 0);
  auto monitor = eamos_test::start_eamos({"monitor", trace, "--port", "0"});
  ASSERT_TRUE(eamos_test::read_until(monitor, "replaying")) << monitor.seen;
  int port = port_of(monitor.seen);
  ASSERT_GT(port, 0) << monitor.seen;
  std::vector<RawClient> idle(40), half(40);
  int upgraded = 0;
  for (RawClient& c : idle) upgraded += c.connect_to(port) && c.websocket_handshake(port, after(5));
  for (RawClient& c : half)
    ASSERT_TRUE(c.connect_to(port) && c.send_all("GET / HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) + "\r\n"));
  std::printf("info: %d of 40 idle WebSockets were upgraded\n", upgraded);
  // Well before any of them times out (3 s), a new page loads, retrying its WebSocket as a page does.
  auto begin = std::chrono::steady_clock::now();
  Deadline until = after(2.0);
  bool loaded = false;
  while (!loaded && std::chrono::steady_clock::now() < until) loaded = load_page(port, until);
  EXPECT_TRUE(loaded);
  std::printf("info: the new page loaded in %.2f s\n",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count());
  // Then the header and hello timeouts close every idle connection.
  for (RawClient& c : half) EXPECT_TRUE(c.closed_by_server(after(10)));
  for (RawClient& c : idle) EXPECT_TRUE(c.closed_by_server(after(10)));
  kill(monitor.pid, SIGTERM);
  eamos_test::Exit e = eamos_test::wait_exit(monitor);
  EXPECT_TRUE(e.exited && e.status == 0) << monitor.seen;
  fs::remove_all(dir);
}

}  // namespace
