// The `eamos` binary end to end: exit status, output files and what a user sees.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/heap_tunables.h"
#include "support/mission_edit.h"
#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;

using eamos_test::Output;
Output eamos(const std::string& args) { return eamos_test::run_eamos(args); }

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

const std::string kListing2 = std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos";

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eamos-cli-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(Cli, CheckAcceptsListing2AndPrintsItsWarning) {
  Output r = eamos("check " + kListing2);
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("ok — 3 drones"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("warning: drone 'Drone2' may run two motion actions"), std::string::npos);
}

// On virtual time `eamos run > FILE` writes its log lines in a few writes, not one per line:
// the file must still hold what a pipe shows, the error after the lines that led to it.
TEST_F(Cli, ARunIntoAFileLogsWhatAPipeShowsInTheSameOrder) {
  const std::string data = std::string(EAMOS_SOURCE_DIR) + "/tests/cli/data/failure/";
  const std::string args = "run " + data + "far-flight.eamos --fleet " + data + "low-battery.yaml";
  Output piped = eamos(args);
  ASSERT_EQ(piped.status, 1) << piped.out;
  ASSERT_NE(piped.out.find("eamos: mission failed"), std::string::npos) << piped.out;
  Output filed = eamos(args + " > " + (dir_ / "log.txt").string());
  EXPECT_EQ(filed.status, 1);
  EXPECT_EQ(read_file(dir_ / "log.txt"), piped.out);
}

/// Write calls (syscw) of `eamos ARGS > FILE` and of the shell that ran it: a shell's
/// /proc/PID/io includes the children it reaped.
long long write_calls_into_file(const std::string& args, const fs::path& file) {
  std::string cmd = "sh -c '" + std::string(EAMOS_BINARY) + " " + args + " > " + file.string() +
                    " 2>&1; grep syscw /proc/$$/io'";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return -1;
  long long calls = -1;
  if (std::fscanf(p, "syscw: %lld", &calls) != 1) calls = -1;
  pclose(p);
  return calls;
}

// A run on virtual time into a regular file writes its log in blocks: a write per line
// was a tenth of a 1,000-drone run's CPU. Through a pipe each line still goes out alone.
TEST_F(Cli, ARunOnVirtualTimeIntoAFileWritesItsLogInBlocks) {
  fs::path mission = dir_ / "show.eamos";
  ASSERT_EQ(eamos("gen-stress --shape show --drones 20 --nodes 1000 -o " + mission.string()).status, 0);
  long long calls = write_calls_into_file("run " + mission.string(), dir_ / "log.txt");
  std::string log = read_file(dir_ / "log.txt");
  long long lines = std::count(log.begin(), log.end(), '\n');
  ASSERT_GT(lines, 500) << log;
  EXPECT_GE(calls, 1);
  EXPECT_LT(calls, lines / 10) << lines << " lines";
  Output piped = eamos("run " + mission.string());
  EXPECT_EQ(piped.out, log);
}

TEST_F(Cli, LogLevelTakesTheFourLevelsOnly) {
  EXPECT_EQ(eamos("--log-level debug check " + kListing2).status, 0);
  EXPECT_EQ(eamos("check " + kListing2 + " --log-level error").status, 0);
  Output r = eamos("--log-level loud check " + kListing2);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("--log-level"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("debug"), std::string::npos) << "the message names the levels: " << r.out;
}

TEST_F(Cli, AnEamosLogLevelThatNamesNoLevelIsAWarningAndTheCommandRuns) {
  setenv("EAMOS_LOG_LEVEL", "loud", 1);
  Output r = eamos("check " + kListing2);
  Output given = eamos("--log-level info check " + kListing2);
  unsetenv("EAMOS_LOG_LEVEL");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("eamos: warning: EAMOS_LOG_LEVEL='loud' is not a log level; info is used"), std::string::npos)
      << r.out;
  EXPECT_EQ(given.out.find("EAMOS_LOG_LEVEL"), std::string::npos) << "--log-level replaces the variable: " << given.out;
}

TEST_F(Cli, CheckFailsWithExitOneAndEveryErrorGccStyle) {
  fs::path m = dir_ / "bad.eamos";
  std::ofstream(m) << "var A Quad\nfunc INIT() {\n  A.Tkeoff(3)\n  B.Land()\n}\n";
  Output r = eamos("check " + m.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find(m.string() + ":3:5: error: drone 'A' of type 'Quad' has no capability 'Tkeoff'; did you mean 'Takeoff'?"),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find(m.string() + ":4:3: error: unknown drone 'B'"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("2 errors, 0 warnings"), std::string::npos) << r.out;
}

TEST_F(Cli, WerrorTurnsWarningsIntoFailure) {
  EXPECT_EQ(eamos("check --werror " + kListing2).status, 1);
  EXPECT_EQ(eamos("check -q " + kListing2).out.find("warning"), std::string::npos);
}

// A fleet whose autopilot link could never open is refused before anything is compiled or
// flown, at the line of each wrong URL, all in one pass.
TEST_F(Cli, AConnectionTheAdapterCouldNotOpenIsAnErrorAtItsLineBeforeAnyFlight) {
  fs::path fleet = dir_ / "fleet.yaml";
  std::ofstream(fleet) << "drones:\n  Drone1:\n    adapter: mavlink\n    connection: serail:///dev/ttyS0:57600\n"
                          "  Drone2:\n    adapter: mavlink\n    connection: serial:///dev/ttyUSB0:12345\n"
                          "  Drone3:\n    adapter: mavlink\n    connection: tcp://127.0.0.1:5760\n";
  for (const std::string& command : {std::string("check "), "compile -o " + (dir_ / "deploy").string() + " "}) {
    Output r = eamos(command + kListing2 + " --fleet " + fleet.string());
    EXPECT_EQ(r.status, 1) << command << r.out;
    EXPECT_NE(r.out.find(fleet.string() + ":4:17: error: connection of drone 'Drone1': unknown scheme 'serail'"),
              std::string::npos) << r.out;
    EXPECT_NE(r.out.find(fleet.string() + ":7:17: error: connection of drone 'Drone2': rate '12345' is not a serial rate"),
              std::string::npos) << r.out;
    EXPECT_NE(r.out.find("2 errors"), std::string::npos) << r.out;
  }
  EXPECT_FALSE(fs::exists(dir_ / "deploy"));
}

TEST_F(Cli, MissingFileIsAClearErrorNotACrash) {
  Output r = eamos("check " + (dir_ / "nope.eamos").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("nope.eamos"), std::string::npos) << r.out;
}

TEST_F(Cli, CompileWritesManifestAndOneMissionFilePerDrone) {
  Output r = eamos("compile -q " + kListing2 + " -o " + (dir_ / "deploy").string());
  ASSERT_EQ(r.status, 0) << r.out;
  auto manifest = nlohmann::json::parse(read_file(dir_ / "deploy" / "manifest.json"));
  ASSERT_EQ(manifest["drones"].size(), 3u);
  std::string hash = manifest["mission_hash"];
  EXPECT_EQ(hash.size(), 64u);
  for (const char* drone : {"Drone1", "Drone2", "Drone3"}) {
    auto m = nlohmann::json::parse(read_file(dir_ / "deploy" / drone / "mission.json"));
    EXPECT_EQ(m["format"], "eamos-mission");
    EXPECT_EQ(m["format_version"], 4);
    EXPECT_EQ(m["mission_hash"], hash);
    EXPECT_EQ(m["drone"]["name"], drone);
    EXPECT_FALSE(m["nodes"].empty());
  }
}

TEST_F(Cli, FleetFileChangesTheMissionHash) {
  fs::path fleet = dir_ / "fleet.yaml";
  std::ofstream(fleet) << "drones:\n  Drone1:\n    sensors:\n      Sensor1: 120\n";
  ASSERT_EQ(eamos("compile -q " + kListing2 + " -o " + (dir_ / "a").string()).status, 0);
  Output r = eamos("compile -q " + kListing2 + " --fleet " + fleet.string() + " -o " + (dir_ / "b").string());
  ASSERT_EQ(r.status, 0) << r.out;
  auto a = nlohmann::json::parse(read_file(dir_ / "a" / "manifest.json"));
  auto b = nlohmann::json::parse(read_file(dir_ / "b" / "manifest.json"));
  EXPECT_NE(a["mission_hash"], b["mission_hash"]);
  auto d1 = nlohmann::json::parse(read_file(dir_ / "b" / "Drone1" / "mission.json"));
  EXPECT_EQ(d1["drone"]["sensors"]["Sensor1"]["value"], 120.0);
}

TEST_F(Cli, GraphRendersSvgThroughGraphviz) {
  fs::path svg = dir_ / "meg.svg";
  Output r = eamos("graph -q " + kListing2 + " --kind meg --format svg -o " + svg.string());
  ASSERT_EQ(r.status, 0) << r.out;
  std::string text = read_file(svg);
  EXPECT_NE(text.find("<svg"), std::string::npos);
  EXPECT_NE(text.find("Drone1.Takeoff(3)"), std::string::npos);
}

TEST_F(Cli, GraphOfMdgNeedsAKnownDrone) {
  Output r = eamos("graph -q " + kListing2 + " --kind mdg --drone Drone9 --format dot");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("no drone 'Drone9'"), std::string::npos) << r.out;
  Output ok = eamos("graph -q " + kListing2 + " --kind mdg --drone Drone2 --format json");
  ASSERT_EQ(ok.status, 0);
  EXPECT_EQ(nlohmann::json::parse(ok.out)["drone"], "Drone2");
}

TEST_F(Cli, ADistributedOnlyRunOptionWithoutDistributedIsRefusedBeforeAnythingFlies) {
  for (const std::string& option : {"--deploy-dir " + (dir_ / "deploy").string(), std::string("--domain 7"),
                                   std::string("--insecure"), std::string("--barrier-timeout 20")}) {
    Output r = eamos("run -q " + kListing2 + " " + option + " --summary " + (dir_ / "s.json").string());
    EXPECT_EQ(r.status, 1) << option << ": " << r.out;
    EXPECT_NE(r.out.find("--distributed"), std::string::npos) << "the refusal names the flag it needs: " << r.out;
    EXPECT_FALSE(fs::exists(dir_ / "s.json")) << option << ": nothing flew";
    EXPECT_FALSE(fs::exists(dir_ / "deploy")) << option;
  }
}

TEST_F(Cli, ALaunchStoppedBeforeTheFlightSaysWhyOnceAndNoEmptyFailureReason) {
  ASSERT_EQ(eamos("compile -q --insecure " + kListing2 + " -o " + (dir_ / "deploy").string()).status, 0);
  Output r = eamos("launch " + (dir_ / "deploy").string() + " --drones Nobody");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("--drones names 'Nobody'"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("mission failed: \n"), std::string::npos) << "a failure without its reason: " << r.out;
}

TEST_F(Cli, StatsCountsNodesPerDrone) {
  Output r = eamos("stats -q " + kListing2);
  ASSERT_EQ(r.status, 0) << r.out;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["drones"], 3);
  EXPECT_EQ(j["mdg"]["per_drone"].size(), 3u);
  EXPECT_EQ(j["meg"]["nodes"].get<int>(), j["meg"]["by_kind"]["action"].get<int>() +
                                              j["meg"]["by_kind"]["condition"].get<int>() +
                                              j["meg"]["by_kind"]["terminal"].get<int>() +
                                              j["meg"]["by_kind"]["fork"].get<int>() +
                                              j["meg"]["by_kind"]["pause"].get<int>() + 2);
}

TEST_F(Cli, GenStressMissionCompilesWithoutWarningsAndIsDeterministic) {
  fs::path a = dir_ / "a.eamos", b = dir_ / "b.eamos";
  ASSERT_EQ(eamos("gen-stress --nodes 2000 --drones 12 -o " + a.string()).status, 0);
  ASSERT_EQ(eamos("gen-stress --nodes 2000 --drones 12 -o " + b.string()).status, 0);
  EXPECT_EQ(read_file(a), read_file(b));
  Output r = eamos("check --werror " + a.string());
  EXPECT_EQ(r.status, 0) << r.out.substr(0, 2000);
  auto stats = nlohmann::json::parse(eamos("stats " + a.string()).out);
  int nodes = stats["meg"]["nodes"];
  EXPECT_GE(nodes, 2000);
  EXPECT_LT(nodes, 2400);
}

// Every file under `dir`, by its path relative to it.
std::map<std::string, std::string> files_under(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out[fs::relative(e.path(), dir).string()] = read_file(e.path());
  return out;
}

// A source of 1 MiB or more restarts `eamos compile` once with glibc's malloc on huge pages
// (src/cli/main.cpp); the restarted process must get the same arguments and write the same
// files, whether the user's GLIBC_TUNABLES is unset, names other tunables (kept, the huge
// pages added) or already chooses huge pages (no restart).
TEST_F(Cli, ALargeCompileWritesTheSameFilesWhetherOrNotItRestartsOnHugePages) {
  fs::path mission = dir_ / "large.eamos";
  ASSERT_EQ(eamos("gen-stress --nodes 40000 --drones 40 -o " + mission.string()).status, 0);
  ASSERT_GE(fs::file_size(mission), std::uintmax_t{1} << 20) << "too small to restart: raise --nodes";
  std::vector<std::map<std::string, std::string>> outputs;
  for (const char* tunables : {"", "glibc.malloc.mmap_threshold=65536", "glibc.malloc.hugetlb=0"}) {
    if (*tunables) setenv("GLIBC_TUNABLES", tunables, 1);
    fs::path out = dir_ / ("out" + std::to_string(outputs.size()));
    Output r = eamos("compile --insecure -q " + mission.string() + " -o " + out.string());
    unsetenv("GLIBC_TUNABLES");
    ASSERT_EQ(r.status, 0) << tunables << ": " << r.out.substr(0, 2000);
    outputs.push_back(files_under(out));
  }
  EXPECT_EQ(outputs[0].size(), 41u + 1u) << "a mission file per drone, one for the ground and the manifest";
  EXPECT_EQ(outputs[0], outputs[1]);
  EXPECT_EQ(outputs[0], outputs[2]);
}

// What `eamos` puts in GLIBC_TUNABLES for run, verify and a large compile: its heap tunables
// in front of the user's, whose later settings win; nothing when theirs choose huge pages.
// (The running process cannot show it: glibc cuts the environment /proc shows at the first
// tunable it reads.)
TEST(HeapTunables, OursComeFirstAndAUsersChoiceOfHugePagesIsLeftAlone) {
  const std::string ours(eamos::cli::kHeapTunables);
  EXPECT_EQ(eamos::cli::heap_tunables(""), ours);
  EXPECT_EQ(eamos::cli::heap_tunables("glibc.malloc.arena_max=2"), ours + ":glibc.malloc.arena_max=2");
  EXPECT_EQ(eamos::cli::heap_tunables("glibc.malloc.trim_threshold=0"), ours + ":glibc.malloc.trim_threshold=0");
  EXPECT_EQ(eamos::cli::heap_tunables("glibc.malloc.hugetlb=0"), std::nullopt);
  EXPECT_EQ(eamos::cli::heap_tunables("glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1"), std::nullopt);
  // The string docs/performance.md and src/cli/README.md give.
  EXPECT_EQ(ours, "glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=33554432:glibc.malloc.trim_threshold=4294967296");
}

TEST_F(Cli, HelpAndVersion) {
  Output v = eamos("--version");
  EXPECT_EQ(v.status, 0);
  EXPECT_NE(v.out.find("eamos 0."), std::string::npos);
  for (const char* sub : {"check", "compile", "graph", "stats", "gen-stress"}) {
    Output h = eamos(std::string(sub) + " --help");
    EXPECT_EQ(h.status, 0) << sub;
    EXPECT_NE(h.out.find("Usage"), std::string::npos) << sub;
  }
  EXPECT_EQ(eamos("frobnicate").status, 1);
}

std::string mission(const std::string& name) { return std::string(EAMOS_SOURCE_DIR) + "/tests/dex/missions/" + name; }

std::vector<nlohmann::json> trace_lines(const fs::path& p) {
  std::vector<nlohmann::json> out;
  std::ifstream in(p);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(nlohmann::json::parse(line));
  return out;
}

// A mission that completes with a drone still up (no Land) or still armed (no Disarm) used to
// end with "mission completed" and nothing else; eamos verify reported it, eamos run did not.
TEST_F(Cli, ARunThatLeavesADroneInTheAirOrArmedSaysSo) {
  fs::path m = dir_ / "ends.eamos";
  std::ofstream(m) << "var A Quad\nvar B Quad\nvar C Quad\nfunc INIT() { PAR_x() }\n"
                      "func PAR_x() { SEQ_a(); SEQ_b(); SEQ_c() }\n"
                      "func SEQ_a() { A.Arm(); A.Takeoff(5) }\n"
                      "func SEQ_b() { B.Arm(); B.Takeoff(5); B.Land() }\n"
                      "func SEQ_c() { C.Arm(); C.Takeoff(5); C.Land(); C.Disarm() }\n";
  Output r = eamos("run -q " + m.string());
  EXPECT_EQ(r.status, 0) << r.out;  // it did complete
  EXPECT_NE(r.out.find("eamos: warning: A is still in the air when the mission ends (z = 5.0 m) and nothing lands "
                       "it; end its part with A.Land() and A.Disarm()"),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("eamos: warning: B is still armed on the ground when the mission ends; end its part with "
                       "B.Disarm()"),
            std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("warning: C "), std::string::npos) << r.out;
  EXPECT_EQ(eamos("run -q " + kListing2).out.find("when the mission ends"), std::string::npos);
}

// At a speed no host follows (a wall microsecond is a mission second), the run's timeline is
// not the plan's: Listing 2 ran for minutes of mission time, or failed with an empty battery,
// and said nothing about it. Now it says how late its events ran and what to do.
TEST_F(Cli, ARunAtASpeedTheHostCannotFollowSaysItsTimingIsNotThePlans) {
  Output r = eamos("run -q " + kListing2 + " --speed 1e6");
  EXPECT_NE(r.out.find("eamos: warning: the host could not keep up with --speed 1e+06: events ran up to "),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("leave it out to run on virtual time"), std::string::npos) << r.out;
  Output planned = eamos("run -q " + kListing2);
  EXPECT_EQ(planned.status, 0) << planned.out;
  EXPECT_EQ(planned.out.find("could not keep up"), std::string::npos) << planned.out;
}

TEST_F(Cli, RunReportsCompletionWhenTheLastAsyncWorkEndsAndTheTraceEndsWithIt) {
  Output r = eamos("run -q " + mission("async_last.eamos") + " --trace " + (dir_ / "t.jsonl").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("mission completed in 2.1 s (mission time)"), std::string::npos) << r.out;
  std::vector<nlohmann::json> trace;
  for (const nlohmann::json& e : trace_lines(dir_ / "t.jsonl"))  // the actions' events and the end
    if (e["event"] == "start" || e["event"] == "end" || e["event"] == "sensor" || e["event"] == "mission")
      trace.push_back(e);
  ASSERT_GE(trace.size(), 2u);
  EXPECT_EQ(trace.back()["event"], "mission");
  EXPECT_EQ(trace.back()["outcome"], "completed");
  EXPECT_EQ(trace.back()["t"], 2.1);
  const nlohmann::json& before = trace[trace.size() - 2];  // the sensor reading of the read that ended last
  EXPECT_EQ(before["text"], "Drone1.Sensor1()");
  EXPECT_EQ(before["t"], 2.1);
}

// A trace that cannot be written (a full disk; /dev/full refuses every write) is said at
// once, before the first drone moves here since the header is the first write; the flight
// goes on as it would, and the exit status says the run's record is incomplete.
TEST_F(Cli, RunWithATraceOnAFullDiskSaysSoAtOnceFliesOnAndExitsNonZero) {
  Output r = eamos("run " + kListing2 + " --fleet " + std::string(EAMOS_SOURCE_DIR) +
                   "/examples/listing2-right.yaml --trace /dev/full --summary " + (dir_ / "summary.json").string());
  EXPECT_EQ(r.status, 1) << r.out;
  std::size_t error = r.out.find("eamos: error: cannot write the trace '/dev/full' (No space left on device)");
  ASSERT_NE(error, std::string::npos) << r.out;
  EXPECT_LT(error, r.out.find("Drone1   start")) << r.out;
  EXPECT_NE(r.out.find("mission completed in"), std::string::npos) << r.out;
  EXPECT_EQ(nlohmann::json::parse(read_file(dir_ / "summary.json"))["status"], "completed");
}

TEST_F(Cli, AsyncWorkInALoopIsNotWarnedAboutAndEveryPictureEndsOnce) {
  Output c = eamos("check " + mission("async_in_loop.eamos"));
  EXPECT_EQ(c.status, 0) << c.out;
  EXPECT_EQ(c.out.find("warning"), std::string::npos) << c.out;
  Output r = eamos("run -q " + mission("async_in_loop.eamos") + " --trace " + (dir_ / "t.jsonl").string() +
                   " --summary " + (dir_ / "s.json").string());
  ASSERT_EQ(r.status, 0) << r.out;
  int started = 0, succeeded = 0;
  for (const nlohmann::json& e : trace_lines(dir_ / "t.jsonl")) {
    if (e.value("text", "") != "Drone1.TakePicture()") continue;
    started += e["event"] == "start";
    succeeded += e["event"] == "end" && e["outcome"] == "succeeded";
  }
  EXPECT_EQ(started, 3);
  EXPECT_EQ(succeeded, 3);
  std::ifstream in(dir_ / "s.json");
  nlohmann::json summary = nlohmann::json::parse(in);
  EXPECT_EQ(summary["drones"]["Drone1"]["pictures"], 3);
  EXPECT_LT(summary["duration"].get<double>(), 60.0);  // not the time limit
}

// A Do* whose condition is false when reached runs neither branch: with the lead's pack
// already below patrol's 98 % it must skip its orbit and still go home, not hover at 10 m
// until the simulator's battery failsafe lands it (955 s, mission failed).
TEST_F(Cli, PatrolWithTheLeadsBatteryAlreadyLowSkipsTheOrbitAndBringsTheLeadHome) {
  Output r = eamos("run -q " + std::string(EAMOS_SOURCE_DIR) + "/examples/patrol.eamos --fleet " + EAMOS_SOURCE_DIR +
                   "/tests/cli/data/patrol-low-battery.yaml --trace " + (dir_ / "t.jsonl").string() +
                   " --summary " + (dir_ / "s.json").string());
  ASSERT_EQ(r.status, 0) << r.out;
  nlohmann::json home, returned;
  bool orbited = false;
  for (const nlohmann::json& e : trace_lines(dir_ / "t.jsonl")) {
    if (e["event"] == "telemetry" && e["drone"] == "Lead" && home.is_null()) home = e;
    if (e["event"] == "start" && e["text"] == "Lead.Orbit(8)") orbited = true;
    if (e["event"] == "end" && e["text"] == "Lead.ReturnHome()") returned = e;
  }
  EXPECT_FALSE(orbited);
  ASSERT_TRUE(returned.is_object()) << r.out;
  EXPECT_EQ(returned["outcome"], "succeeded");
  std::ifstream in(dir_ / "s.json");
  nlohmann::json summary = nlohmann::json::parse(in);
  EXPECT_EQ(summary["status"], "completed") << r.out;
  const nlohmann::json& lead = summary["drones"]["Lead"];
  EXPECT_NEAR(lead["x"].get<double>(), home["x"].get<double>(), 0.5);
  EXPECT_NEAR(lead["y"].get<double>(), home["y"].get<double>(), 0.5);
  EXPECT_TRUE(lead["landed"].get<bool>());
  EXPECT_FALSE(lead["armed"].get<bool>());
  EXPECT_GT(lead["battery"].get<double>(), 90.0);  // home on its own, not by the failsafe
}

/// "first+rest+rest+…" with `terms` terms: a left-leaning tree `terms` levels deep.
std::string sum(const std::string& first, const std::string& rest, int terms) {
  std::string s = first;
  for (int i = 1; i < terms; ++i) s += "+" + rest;
  return s;
}

/// A one-drone mission whose Takeoff (line 5, its argument from column 13) climbs `altitude`.
std::string taking_off_to(const std::string& altitude) {
  return "var D Quad\nfunc INIT() { SEQ_a() }\nfunc SEQ_a() {\n  D.Arm()\n  D.Takeoff(" + altitude +
         ")\n  D.Land()\n}\n";
}

// Each operator is a level of the expression as the mission file stores it: a long sum is as
// deep as its terms, and deeper than the mission reader takes, so every command refuses it
// where it is written, as it refuses 201 parentheses, instead of overflowing the stack.
TEST_F(Cli, ASumOfTwentyThousandTermsIsAnErrorAtItsLineNotACrash) {
  fs::path m = dir_ / "long_sum.eamos";
  std::ofstream(m) << taking_off_to(sum("1", "1", 20000));
  for (const std::string& command :
       std::vector<std::string>{"check ", "compile -q -o " + (dir_ / "out").string() + " ", "run -q "}) {
    Output r = eamos(command + m.string());
    EXPECT_EQ(r.status, 1) << command << r.out.substr(0, 300);
    EXPECT_EQ(r.out.rfind(m.string() + ":5:412: error: expression nested too deeply (more than 200 levels", 0), 0u)
        << command << r.out.substr(0, 300);
  }
  EXPECT_FALSE(fs::exists(dir_ / "out" / "D" / "mission.json"));
}

// The compiler's limit is the one the mission reader holds files to, counted alike: what
// `eamos check` accepts, `eamos run` (which reads the compiled files back) flies.
TEST_F(Cli, AnExpressionAtTheDepthLimitFliesAndOneLevelMoreIsAnError) {
  fs::path at_limit = dir_ / "at_limit.eamos", over = dir_ / "over.eamos";
  std::ofstream(at_limit) << taking_off_to(sum("5", "0", 200));
  std::ofstream(over) << taking_off_to(sum("5", "0", 201));
  Output r = eamos("run -q " + at_limit.string());
  EXPECT_EQ(r.status, 0) << r.out.substr(0, 600);
  r = eamos("check " + over.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out.rfind(over.string() + ":5:412: error: expression nested too deeply", 0), 0u) << r.out.substr(0, 300);
}

}  // namespace

// `eamos dex` reads its mission through the one validating reader: a damaged or edited
// file ends the process with "FILE: error: WHERE: WHAT" and exit 1, before it joins DDS.
class CliDex : public Cli {
 protected:
  void SetUp() override {
    Cli::SetUp();
    Output r = eamos_test::run_eamos("compile -q " + kListing2 + " -o " + (dir_ / "deploy").string());
    ASSERT_EQ(r.status, 0) << r.out;
    file_ = dir_ / "deploy" / "Drone1" / "mission.json";
    text_ = read_file(file_);
  }
  Output dex_with(const std::string& text) {
    std::ofstream(file_, std::ios::binary | std::ios::trunc) << text;
    return eamos_test::run_eamos("dex " + (dir_ / "deploy" / "Drone1").string() + " --domain 51 --start-timeout 1");
  }
  /// `eamos dex` on the folder as it stands, bounded in time and memory: a reader that waits
  /// for a FIFO's writer or reads /dev/zero for ever fails the test instead of hanging it or
  /// taking the machine's memory.
  Output dex_bounded() {
#ifdef EAMOS_SANITIZED
    std::string limit = "";  // the sanitizer's shadow memory needs the whole address space
#else
    std::string limit = "ulimit -v 2000000; ";
#endif
    std::string cmd = limit + "timeout 60 " + std::string(EAMOS_BINARY) + " dex " +
                      (dir_ / "deploy" / "Drone1").string() + " --domain 51 --start-timeout 1 2>&1";
    Output r;
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return r;
    char buf[4096];
    while (fgets(buf, sizeof buf, p)) r.out += buf;
    int raw = pclose(p);
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    return r;
  }
  fs::path file_;
  std::string text_;
};

TEST_F(CliDex, RefusesAMissionFileThatIsAFifoWithoutWaitingForAWriter) {
  fs::remove(file_);
  ASSERT_EQ(mkfifo(file_.c_str(), 0600), 0);
  Output r = dex_bounded();
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find(file_.string() + ": error: a FIFO, not a regular file; a mission file is the mission.json "
                                        "`eamos compile` writes"),
            std::string::npos)
      << r.out;
}

TEST_F(CliDex, RefusesAMissionFileThatIsADeviceSuchAsDevZero) {
  fs::remove(file_);
  fs::create_symlink("/dev/zero", file_);
  Output r = dex_bounded();
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find(file_.string() + ": error: a character device, not a regular file;"), std::string::npos) << r.out;
}

// One byte over the documented 1 GiB: refused by its size, unread (the file is sparse).
TEST_F(CliDex, RefusesAMissionFileLargerThanTheLimitWithoutReadingIt) {
  fs::resize_file(file_, (std::uintmax_t{1} << 30) + 1);
  Output r = dex_bounded();
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find(file_.string() + ": error: 1073741825 bytes, more than the 1073741824 (1 GiB) a mission file may "
                                        "hold;"),
            std::string::npos)
      << r.out;
}

TEST_F(CliDex, RefusesAMissionFileEditedAfterCompile) {
  Output r = dex_with(eamos_test::replace_once(text_, "\"battery\":100.0", "\"battery\":99.0"));
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out, file_.string() + ": error: /file_hash: the file's content does not match its hash; it was "
                                    "edited or damaged after `eamos compile` (compile the mission again)\n");
}

TEST_F(CliDex, RefusesAnArcToANodeThatIsNotInTheFile) {
  auto doc = nlohmann::json::parse(text_);
  const auto& arc = doc["arcs"][0];
  std::string was = "\n  [" + arc[0].dump() + "," + arc[1].dump() + ",";  // the arc's own line
  std::string now = "\n  [" + arc[0].dump() + ",123456,";
  Output r = dex_with(eamos_test::reseal(eamos_test::replace_once(text_, was, now)));
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out, file_.string() + ": error: /arcs/0/1: 123456 is out of range (0 to " +
                       std::to_string(doc["nodes"].size() - 1) + ")\n");
}

TEST_F(CliDex, RefusesAReadOfADroneOutsideTheFleet) {
  bool none = nlohmann::json::parse(text_)["reads"].empty();
  std::string now = none ? "\"reads\":[\"Ghost\"" : "\"reads\":[\"Ghost\",";
  Output r = dex_with(eamos_test::reseal(eamos_test::replace_once(text_, "\"reads\":[", now)));
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out, file_.string() + ": error: /reads/0: drone \"Ghost\" is not in the mission's fleet\n");
}

TEST_F(CliDex, RefusesAnExpressionNestedTooDeeplyInsteadOfOverflowingTheStack) {
  std::string deep;
  for (int i = 0; i < 100000; ++i) deep += "{\"op\":\"-\",\"args\":[";
  deep += "{\"num\":1.0}";
  for (int i = 0; i < 100000; ++i) deep += "]}";
  std::string text = text_;
  std::size_t at = text.find("\"args\":[{\"num\":");
  ASSERT_NE(at, std::string::npos);
  text.insert(at + 8, deep + ",");
  Output r = dex_with(eamos_test::reseal(text));
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out.rfind(file_.string() + ": error: nested more than", 0), 0u) << r.out.substr(0, 300);
}
