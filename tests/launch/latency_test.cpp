// How late each message between drones arrived: every trigger's latency
// is in the merged trace, the ground warns for each one later than --trigger-latency-warn
// and reports the maximum and p99 in its summary, and --max-trigger-latency makes such a
// message a fault. Real `eamos launch` processes on loopback, DDS domains 190-192. A late
// message is made by something real: the receiving DEX frozen (SIGSTOP) while the trigger
// to it is sent, and resumed when another drone's flight (the event, not a timer) is over.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/types.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "trace/trace_schema.h"
#include "support/eamos_process.h"
#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;
using eamos_test::Output;

std::vector<nlohmann::json> read_trace(const fs::path& p) {
  std::vector<nlohmann::json> events;
  std::ifstream in(p);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) events.push_back(nlohmann::json::parse(line));
  return events;
}

std::string check_errors(const fs::path& p) {
  std::ifstream in(p);
  std::string all;
  for (const std::string& e : eamos::trace::check_trace(in, {.strict = true})) all += e + "\n";
  return all;
}

pid_t dex_pid(const std::string& out, const std::string& drone) {
  std::string key = "started the DEX of " + drone + " (pid ";
  auto at = out.find(key);
  return at == std::string::npos ? -1 : std::stoi(out.substr(at + key.size()));
}

class Latency : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eamos-latency-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    Output c = eamos_test::run_eamos("compile -q " + std::string(EAMOS_SOURCE_DIR) +
                                     "/tests/launch/missions/hops.eamos -o " + (dir_ / "deploy").string());
    ASSERT_EQ(c.status, 0) << c.out;
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  /// `eamos launch` of hops.eamos with `extra` arguments; B's DEX is frozen from C's takeoff
  /// (so C's trigger to B, sent when C is up, waits in B's socket) until A has flown out on
  /// the same trigger (several mission seconds).
  /// `b_elsewhere`: B's DEX, started by the test (the ground starts the others), or -1.
  Output launch_with_b_frozen(const std::string& extra, pid_t b_elsewhere = -1) {
    pid_t b = -1;
    bool resumed = false;
    std::string seen;
    Output r = eamos_test::run_eamos(
        "launch " + (dir_ / "deploy").string() + " --speed 10 --liveliness-timeout 3 --trace " +
            (dir_ / "trace.jsonl").string() + " --summary " + (dir_ / "summary.json").string() + " " + extra,
        [&](const std::string& line) {
          seen += line;
          if (b < 0 && line.find(" start ") != std::string::npos && line.find("C.Takeoff(5)") != std::string::npos) {
            b = b_elsewhere > 0 ? b_elsewhere : dex_pid(seen, "B");
            if (b > 0) kill(b, SIGSTOP);
          }
          if (b > 0 && !resumed && line.find("A.FlyTo(10, 0, 5)  succeeded") != std::string::npos) {
            kill(b, SIGCONT);
            resumed = true;
          }
        });
    EXPECT_TRUE(resumed) << r.out;
    if (b > 0 && !resumed) kill(b, SIGCONT);
    if (std::getenv("EAMOS_LATENCY_VERBOSE")) std::cout << r.out << std::flush;
    return r;
  }
  nlohmann::json summary() {
    std::ifstream in(dir_ / "summary.json");
    return nlohmann::json::parse(in);
  }
  fs::path dir_;
};

TEST_F(Latency, LateTriggerIsWarnedOnTheConsoleAndInTheSummaryAndTheMissionCompletes) {
  Output r = launch_with_b_frozen("--domain 190");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("ground: warning: trigger from C to B (node "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("later than --trigger-latency-warn 0.5 s"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("message latency: max "), std::string::npos) << r.out;

  // The trace keeps the schema and says each message's latency, the late one included.
  EXPECT_EQ(check_errors(dir_ / "trace.jsonl"), "");
  int messages = 0;
  double max_latency = 0;
  for (const nlohmann::json& e : read_trace(dir_ / "trace.jsonl")) {
    if (e["event"] != "message" || (e["kind"] != "trigger" && e["kind"] != "cancel")) continue;
    ++messages;
    ASSERT_TRUE(e.contains("latency")) << e.dump();
    EXPECT_NEAR(e["latency"].get<double>(), e["received"].get<double>() - e["sent"].get<double>(), 2e-6);
    max_latency = std::max(max_latency, e["latency"].get<double>());
  }
  nlohmann::json m = summary()["messages"];
  ASSERT_TRUE(m.is_object()) << summary().dump(2);
  EXPECT_EQ(m["count"], messages);
  EXPECT_NEAR(m["latency_max"].get<double>(), max_latency, 2e-6);
  EXPECT_LE(m["latency_p99"].get<double>(), m["latency_max"].get<double>());
  EXPECT_EQ(m["warn_above"], 0.5);
  ASSERT_FALSE(m["late"].empty()) << m.dump(2);
  bool c_to_b = false;
  for (const nlohmann::json& l : m["late"]) {
    EXPECT_GT(l["latency"].get<double>(), 0.5) << l.dump();
    c_to_b |= l["from"] == "C" && l["to"] == "B" && l["kind"] == "trigger";
  }
  EXPECT_TRUE(c_to_b) << m.dump(2);
  // Nothing else was late: the messages around the freeze came in time.
  EXPECT_LT(m["late"].size(), static_cast<std::size_t>(messages));
}

TEST_F(Latency, TriggerLaterThanTheMaximumFailsTheMissionIntoEveryDronesFailsafe) {
  Output r = launch_with_b_frozen("--domain 191 --max-trigger-latency 0.5");
  EXPECT_EQ(r.status, 1) << r.out;
  nlohmann::json s = summary();
  EXPECT_EQ(s["status"], "failed") << s.dump(2);
  std::string error = s.value("error", "");
  EXPECT_NE(error.find("trigger from C to B (node "), std::string::npos) << error;
  EXPECT_NE(error.find("later than --max-trigger-latency 0.5 s"), std::string::npos) << error;
  // Every drone was in the air (A and B hovering, C just up) and ran its failsafe: B first,
  // on the late trigger it did not obey, A and C on B's ABORT.
  std::map<std::string, int> failsafes;
  for (const nlohmann::json& e : read_trace(dir_ / "trace.jsonl"))
    if (e["event"] == "failsafe") ++failsafes[e["drone"].get<std::string>()];
  EXPECT_EQ(failsafes, (std::map<std::string, int>{{"A", 1}, {"B", 1}, {"C", 1}})) << r.out;
  for (const char* d : {"A", "B", "C"}) EXPECT_TRUE(s["drones"][d]["landed"]) << d << "\n" << s.dump(2);
  EXPECT_EQ(check_errors(dir_ / "trace.jsonl"), "");
}

// B's DEX started elsewhere (here: by the test) without the bound: the ground holds it for
// B and aborts the run when it hears of the late trigger.
TEST_F(Latency, TriggerLateToADexStartedElsewhereFailsTheMissionOnTheGroundsBound) {
  eamos_test::EamosProcess b = eamos_test::start_eamos(
      {"dex", (dir_ / "deploy" / "B").string(), "--speed", "10", "--liveliness-timeout", "3", "--domain", "192",
       "--start-timeout", "60"});
  ASSERT_GT(b.pid, 0);
  Output r = launch_with_b_frozen("--domain 192 --drones A,C --max-trigger-latency 0.5", b.pid);
  eamos_test::Exit b_exit = eamos_test::wait_exit(b);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_EQ(b_exit.status, 1) << b.seen;
  std::string error = summary().value("error", "");
  EXPECT_NE(error.find("trigger from C to B (node "), std::string::npos) << error;
  EXPECT_NE(error.find("(held by the ground: B's DEX was started elsewhere)"), std::string::npos) << error;
  std::map<std::string, int> failsafes;
  for (const nlohmann::json& e : read_trace(dir_ / "trace.jsonl"))
    if (e["event"] == "failsafe") ++failsafes[e["drone"].get<std::string>()];
  EXPECT_EQ(failsafes, (std::map<std::string, int>{{"A", 1}, {"B", 1}, {"C", 1}})) << r.out << b.seen;
}

}  // namespace
