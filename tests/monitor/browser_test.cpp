// The monitor's page in a real browser (Debian's chromium, headless, driven by puppeteer-core
// from browser/monitor_check.js) against the real `eamos` process: a replay of a trace the
// test flies first, and a live run. Screenshots go to the build's tests/monitor/screenshots.
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <set>
#include <filesystem>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "support/eamos_process.h"
#include "support/run_eamos.h"
#include "support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using eamos_test::ScratchDir;

bool have_chromium() { return std::string(EAMOS_CHROMIUM).size() > 0 && access(EAMOS_CHROMIUM, X_OK) == 0; }

// The URL the process printed ("... at http://127.0.0.1:PORT/"), "" when it printed none.
std::string read_url(eamos_test::EamosProcess& p, const std::string& marker) {
  if (!eamos_test::read_until(p, marker)) return "";
  std::size_t at = p.seen.rfind("http://");
  if (at == std::string::npos) return "";
  std::size_t end = p.seen.find_first_of(" \n", at);
  return p.seen.substr(at, end - at);
}

// Runs the browser script; its output, and whether every check passed.
bool run_browser(const std::string& mode, const std::string& url, std::string& output) {
  // EAMOS_TEST_PID: the script tells this test's processes from other work on the host.
  std::string cmd = "cd '" + std::string(EAMOS_BROWSER_DIR) + "' && EAMOS_TEST_PID=" + std::to_string(getpid()) + " '" +
                    EAMOS_NODE + "' monitor_check.js " + mode +
                    " '" + url + "' '" + EAMOS_SCREENSHOT_DIR + "' '" + EAMOS_CHROMIUM + "' 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return false;
  char buf[4096];
  while (fgets(buf, sizeof buf, p)) output += buf;
  int status = pclose(p);
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

void stop(eamos_test::EamosProcess& p, int& status) {
  kill(p.pid, SIGTERM);
  eamos_test::Exit e = eamos_test::wait_exit(p);
  status = e.exited ? e.status : -1;
}

// What a browser check of a replay saw: whether `eamos monitor` served a page, whether every
// check of the script passed (and its output), and how the monitor ended when stopped.
struct ReplayCheck {
  bool served = false;
  bool passed = false;
  int status = -1;
  std::string output, seen;
};

// `eamos monitor TRACE --port 0 EXTRA...` replaying, the browser script's MODE against its
// page, then the monitor stopped as Ctrl-C stops it.
ReplayCheck replay_in_browser(const std::string& trace, const std::string& mode,
                              const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args = {"monitor", trace, "--port", "0"};
  args.insert(args.end(), extra.begin(), extra.end());
  auto monitor = eamos_test::start_eamos(args);
  ReplayCheck c;
  if (monitor.pid <= 0) return c;
  std::string url = read_url(monitor, "replaying");
  c.served = !url.empty();
  if (c.served) c.passed = run_browser(mode, url, c.output);
  stop(monitor, c.status);
  c.seen = monitor.seen;
  return c;
}

void expect_passed(const ReplayCheck& c) {
  EXPECT_TRUE(c.served) << c.seen;
  EXPECT_TRUE(c.passed) << c.output;
  EXPECT_EQ(c.status, 0) << c.seen;
}

TEST(MonitorBrowser, ReplayOfListing2ShowsLanesTriggerAndNodeStates) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/install-deps.sh does)";
  ScratchDir dir("monitor-replay");
  std::string trace = dir / "listing2.jsonl";
  auto run = eamos_test::run_eamos("run examples/listing2.eamos -q --trace " + trace);
  ASSERT_EQ(run.status, 0) << run.out;
  // --mission: a trace written before traces carried their mission still gets its graphs.
  expect_passed(replay_in_browser(trace, "replay", {"--mission", "examples/listing2.eamos"}));
  EXPECT_TRUE(fs::exists(fs::path(EAMOS_SCREENSHOT_DIR) / "replay-listing2-t5.png"));
}

// A trace as schema v1 (docs/trace.md) has it: the header line with the mission's text, a
// telemetry line per drone and sample, and message lines. Made from a real trace of Listing 2
// with a hand-written header, a flight of Drone1 along x and one trigger message.
std::string v1_trace(const std::string& real_trace) {
  std::ifstream mission("examples/listing2.eamos");
  std::string source((std::istreambuf_iterator<char>(mission)), {});
  nlohmann::json header = {{"t", 0}, {"event", "header"}, {"schema", "eamos-trace"}, {"version", 1},
                           {"mission", "listing2.eamos"}, {"mission_hash", "x"}, {"source", source}, {"fleet", ""},
                           {"drones", {{{"name", "Drone1"}, {"index", 0}, {"type", "DroneType1"}, {"home", {0, 0, 0}}},
                                       {{"name", "Drone2"}, {"index", 1}, {"type", "DroneType2"}, {"home", {0, 5, 0}}},
                                       {{"name", "Drone3"}, {"index", 2}, {"type", "DroneType3"}, {"home", {0, 10, 0}}}}},
                           {"telemetry_hz", 5}};
  std::string out = header.dump() + "\n";
  std::ifstream in(real_trace);
  std::string line;
  // The real run's own header, telemetry and messages make way for the hand-written ones,
  // so that what the page shows can only have come from these.
  while (std::getline(in, line)) {
    std::string event = nlohmann::json::parse(line, nullptr, false).value("event", "");
    if (event != "header" && event != "telemetry" && event != "message") out += line + "\n";
  }
  for (double t : {0.0, 2.0, 3.0, 5.0})
    out += nlohmann::json({{"t", t}, {"event", "telemetry"}, {"drone", "Drone1"}, {"x", t <= 2 ? 0.0 : -(t - 2) * 2},
                           {"y", 0.0}, {"z", t > 0 ? 4.0 : 0.0}, {"heading", 0}, {"armed", true}, {"landed", false},
                           {"battery", 99.0}, {"mode", "sim"}}).dump() + "\n";
  out += nlohmann::json({{"t", 3.75}, {"event", "message"}, {"kind", "trigger"}, {"from", "Drone1"}, {"to", "Drone3"},
                         {"node", 23}, {"sent", 3.7}, {"received", 3.75}}).dump() + "\n";
  return out;
}

TEST(MonitorBrowser, ReplayOfASchemaV1TraceUsesItsHeaderTelemetryAndMessages) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/install-deps.sh does)";
  ScratchDir dir("monitor-v1");
  std::string real = dir / "real.jsonl", trace = dir / "v1.jsonl";
  auto run = eamos_test::run_eamos("run examples/listing2.eamos -q --trace " + real);
  ASSERT_EQ(run.status, 0) << run.out;
  std::ofstream(trace) << v1_trace(real);
  expect_passed(replay_in_browser(trace, "v1"));
}

TEST(MonitorBrowser, ReplayOfAVerifyTraceMarksTheViolationInRedInItsLane) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/install-deps.sh does)";
  ScratchDir dir("monitor-verify");
  std::string trace = dir / "separation.jsonl";
  auto run = eamos_test::run_eamos("verify -q tests/verify/missions/separation.eamos --fleet "
                                   "tests/verify/missions/separation.fleet.yaml --trace " + trace);
  ASSERT_EQ(run.status, 1) << run.out;  // the mission breaks the separation rule
  expect_passed(replay_in_browser(trace, "violation"));
}

TEST(MonitorBrowser, ReplayShowsWhoGaveWayToWhomInItsLane) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/install-deps.sh does)";
  ScratchDir dir("monitor-give-way");
  std::string trace = dir / "crossing.jsonl";
  auto run = eamos_test::run_eamos("run -q tests/launch/missions/separation_crossing.eamos --fleet "
                                   "tests/launch/missions/separation_crossing.yaml --trace " + trace);
  ASSERT_EQ(run.status, 0) << run.out;
  expect_passed(replay_in_browser(trace, "giveway"));
}

TEST(MonitorBrowser, AThousandDroneReplayDrawsItsLanesOnACanvas) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/install-deps.sh does)";
  ScratchDir dir("monitor-scale");
  std::string mission = dir / "fleet.eamos", trace = dir / "fleet.jsonl";
  ASSERT_EQ(eamos_test::run_eamos("gen-stress --drones 1000 --nodes 20000 -o " + mission).status, 0);
  auto run = eamos_test::run_eamos("run " + mission + " -q --trace " + trace + " > /dev/null");
  ASSERT_EQ(run.status, 0) << run.out;
  expect_passed(replay_in_browser(trace, "scale", {"--mission", mission}));
}

// Each drone's altitude line in a `--plot` SVG: drone name -> "#RRGGBB".
std::map<std::string, std::string> plot_colours(const fs::path& svg_file) {
  std::ifstream in(svg_file);
  std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  static const std::regex line("<polyline class=\"altitude\" data-drone=\"([^\"]+)\" points=\"[^\"]*\" "
                               "fill=\"none\" stroke=\"(#[0-9A-Fa-f]{6})\"");
  std::map<std::string, std::string> colours;
  for (std::sregex_iterator m(svg.begin(), svg.end(), line), end; m != end; ++m) colours[(*m)[1]] = (*m)[2];
  return colours;
}

// The page has no colour rule of its own: past eight drones it once repeated a palette of
// sixteen while the SVGs went on with new hues, so drone 9 had two colours.
TEST(MonitorBrowser, EachOfTwentyDronesHasTheSameColourInThePageAsInThePlot) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/install-deps.sh does)";
  ScratchDir dir("monitor-palette");
  std::string mission = dir / "fleet.eamos", trace = dir / "fleet.jsonl";
  ASSERT_EQ(eamos_test::run_eamos("gen-stress --drones 20 --nodes 60 -o " + mission).status, 0);
  auto run = eamos_test::run_eamos("run " + mission + " -q --trace " + trace + " --plot " + dir / "plot.svg" +
                                   " > /dev/null");
  ASSERT_EQ(run.status, 0) << run.out;
  std::map<std::string, std::string> plot = plot_colours(dir / "plot.svg");
  ASSERT_EQ(plot.size(), 20u);
  std::set<std::string> distinct;
  for (const auto& [drone, colour] : plot) distinct.insert(colour);
  EXPECT_EQ(distinct.size(), 20u) << "every drone of the plot has a colour of its own";

  ReplayCheck c = replay_in_browser(trace, "palette", {"--mission", mission});
  ASSERT_TRUE(c.served && c.passed) << c.seen << c.output;
  const std::string& output = c.output;
  std::size_t at = output.find("colours: ");
  ASSERT_NE(at, std::string::npos) << output;
  nlohmann::json page = nlohmann::json::parse(output.substr(at + 9, output.find('\n', at) - at - 9), nullptr, false);
  ASSERT_TRUE(page.is_object()) << output;
  for (const auto& [drone, colour] : plot) {
    ASSERT_TRUE(page.contains(drone)) << drone << " is not in the page's list: " << output;
    EXPECT_EQ(page[drone].get<std::string>(), colour) << drone;
  }
}

TEST(MonitorBrowser, LiveRunProgressesAndSurvivesReloadAndSecondPage) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/install-deps.sh does)";
  // In real time the 16.7 s mission flies long enough for a browser to start on a loaded
  // machine and watch it move (at 2x, a browser slow to start once saw only the end).
  auto run = eamos_test::start_eamos({"run", "examples/listing2.eamos", "-q", "--realtime", "--monitor", "127.0.0.1:0"});
  ASSERT_GT(run.pid, 0);
  std::string url = read_url(run, "monitor at");
  ASSERT_FALSE(url.empty()) << run.seen;
  std::string output;
  bool passed = run_browser("live", url, output);
  std::cout << output;  // what was checked, and the measured live latency
  // The page stays up after the end until the user stops it; the run's status is the mission's.
  bool held = eamos_test::read_until(run, "until Ctrl-C");
  int status = -1;
  stop(run, status);
  EXPECT_TRUE(passed) << output;
  EXPECT_TRUE(held) << run.seen;
  EXPECT_EQ(status, 0) << run.seen;
  EXPECT_NE(run.seen.find("mission completed in 16.7 s"), std::string::npos) << run.seen;
  // The signal that stops the page says so, rather than announcing every drone's failsafe.
  EXPECT_NE(run.seen.find("interrupted (SIGTERM): the mission has ended; the monitor stops"), std::string::npos)
      << run.seen;
  EXPECT_EQ(run.seen.find("failsafe"), std::string::npos) << run.seen;
}

}  // namespace

namespace {

// The monitor's latency bound: at 20 drones a live page draws each event within 100 ms of eamos emitting
// it (p95; the page measures it from the wall-clock stamps eamos sends beside live events). In
// real time; the browser measures 800 live events and the run is then stopped.
TEST(MonitorBrowser, LiveTwentyDronesAreDrawnWithin100msOfEachEvent) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/install-deps.sh does)";
  ScratchDir dir("monitor-live20");
  std::string mission = dir / "fleet.eamos";
  ASSERT_EQ(eamos_test::run_eamos("gen-stress --drones 20 --nodes 120 -o " + mission).status, 0);
  auto run = eamos_test::start_eamos({"run", mission, "-q", "--realtime", "--monitor", "127.0.0.1:0"});
  ASSERT_GT(run.pid, 0);
  std::string url = read_url(run, "monitor at");
  ASSERT_FALSE(url.empty()) << run.seen;
  // Read the log to its end as a terminal would while the browser watches: a full pipe would stall the mission.
  std::thread reader([&] { eamos_test::read_until(run, std::string(1, '\0')); });
  std::string output;
  bool passed = run_browser("live20", url, output);
  std::cout << output;  // the measured median, p95 and max
  kill(run.pid, SIGTERM);  // Ctrl-C: the drones' failsafe, then the report
  reader.join();
  eamos_test::Exit e = eamos_test::wait_exit(run);
  EXPECT_TRUE(passed) << output;
  EXPECT_TRUE(e.exited) << run.seen;
}

// Latency at a thousand drones: a show (every drone in every PAR, five fleet-wide barriers)
// in real time, lanes on the canvas, each event drawn within the monitor's bound of 100 ms of
// eamos emitting it (p95 over 8,000 live events, telemetry included: about three seconds),
// the page's renders under 8 ms (median); the run is then stopped. Real time, as a live
// flight is watched; faster replays miss now and then on a shared 2-core host
// (docs/performance.md has the runs). A miss while processes other than this test's took more
// than a quarter of the machine skips the case (with the figures) instead of failing it: other
// work then delays Chromium's processes, not the page's script; the other checks hold regardless. What keeps a
// thousand-drone page within it (docs/monitor.md): the mission text laid out only in view,
// tracks kept as layers, the server's events batched into one message per 8 ms, and the
// lanes canvas kept in columns of which a frame redraws only those that changed.
TEST(MonitorBrowser, LiveThousandDronesAreDrawnWithin100msOfEachEvent) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/install-deps.sh does)";
  ScratchDir dir("monitor-live1000");
  std::string mission = dir / "show.eamos";
  ASSERT_EQ(eamos_test::run_eamos("gen-stress --shape show --drones 1000 --work 1 --nodes 5200 -o " + mission).status, 0);
  auto run = eamos_test::start_eamos({"run", mission, "-q", "--realtime", "--monitor", "127.0.0.1:0"});
  ASSERT_GT(run.pid, 0);
  std::string url = read_url(run, "monitor at");
  ASSERT_FALSE(url.empty()) << run.seen;
  std::thread reader([&] { eamos_test::read_until(run, std::string(1, '\0')); });
  std::string output;
  bool passed = run_browser("live1000", url, output);
  std::cout << output;  // the measured median, p95 and max, and the page's render times
  kill(run.pid, SIGTERM);
  reader.join();
  eamos_test::Exit e = eamos_test::wait_exit(run);
  EXPECT_TRUE(passed) << output;
  EXPECT_TRUE(e.exited) << run.seen;
  // Every other check held; the bound was missed on a host loaded by other work.
  std::size_t skip = output.find("skip: ");
  if (passed && skip != std::string::npos) GTEST_SKIP() << output.substr(skip, output.find('\n', skip) - skip);
}

}  // namespace

namespace {

// `eamos launch DIR --monitor`: one DEX process per drone over DDS (domain 202, used by no
// other test), the ground serving the page; the browser watches Listing 2 to its end.
TEST(MonitorBrowser, LaunchOfADeploymentIsServedLiveToItsEnd) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/install-deps.sh does)";
  ScratchDir dir("monitor-launch");
  std::string deploy = dir / "deploy";
  auto compiled = eamos_test::run_eamos("compile -q --insecure examples/listing2.eamos -o " + deploy);
  ASSERT_EQ(compiled.status, 0) << compiled.out;
  // --speed 2: the 16.7 s mission flies for 8 s, long enough for the browser to join mid-flight.
  auto launch = eamos_test::start_eamos({"launch", deploy, "--insecure", "--speed", "2", "--domain", "202",
                                         "--monitor", "127.0.0.1:0"});
  ASSERT_GT(launch.pid, 0);
  std::string url = read_url(launch, "monitor at");
  ASSERT_FALSE(url.empty()) << launch.seen;
  bool held = false;
  std::thread reader([&] { held = eamos_test::read_until(launch, "until Ctrl-C"); });
  std::string output;
  bool passed = run_browser("launch", url, output);
  reader.join();
  int status = -1;
  stop(launch, status);
  EXPECT_TRUE(passed) << output;
  EXPECT_TRUE(held) << launch.seen;
  EXPECT_EQ(status, 0) << launch.seen;
  EXPECT_NE(launch.seen.find("mission completed"), std::string::npos) << launch.seen;
}

}  // namespace

namespace {

// A failed live run must stop saying "● live" and show a banner with the reason. tests/monitor/missions/timeout.eamos fails at 3.65 s; its drones land until 8.2 s.
TEST(MonitorBrowser, AFailedLiveRunShowsItsFailureAndNoLongerSaysLive) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/install-deps.sh does)";
  auto run = eamos_test::start_eamos({"run", "tests/monitor/missions/timeout.eamos", "--fleet",
                                      "tests/monitor/missions/timeout.fleet.yaml", "-q", "--realtime", "--monitor",
                                      "127.0.0.1:0"});
  ASSERT_GT(run.pid, 0);
  std::string url = read_url(run, "monitor at");
  ASSERT_FALSE(url.empty()) << run.seen;
  bool held = false;
  std::thread reader([&] { held = eamos_test::read_until(run, "until Ctrl-C"); });
  std::string output;
  bool passed = run_browser("failed", url, output);
  std::cout << output;
  reader.join();
  int status = -1;
  stop(run, status);
  EXPECT_TRUE(passed) << output;
  EXPECT_TRUE(held) << run.seen;
  EXPECT_EQ(status, 1) << run.seen;  // the mission's status: failed
}

// The end of a four-drone PAR: every drone waits for the slowest; one labelled span per pause.
TEST(MonitorBrowser, WaitSpansOfAFourDroneParNeitherOverlapNorOverflow) {
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/install-deps.sh does)";
  ScratchDir dir("monitor-par4");
  std::string trace = dir / "par4.jsonl";
  auto run = eamos_test::run_eamos("run tests/monitor/missions/par4.eamos -q --trace " + trace);
  ASSERT_EQ(run.status, 0) << run.out;
  expect_passed(replay_in_browser(trace, "waits"));
}

}  // namespace
