// The mission as separate processes: `eamos launch` / `eamos run --distributed` start one
// DEX per drone and a ground process, all over Cyclone DDS on loopback (the shipped
// configuration). Each test has its own DDS domain. Missions run in real time, five times
// faster than the wall clock, so these tests take seconds, not minutes; nothing here
// sleeps: the tests block on the processes' output.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "trace/trace_schema.h"
#include "support/mission_edit.h"
#include "support/read_files.h"
#include "support/run_eamos.h"
#include "transport/dds_node.h"

namespace {

namespace fs = std::filesystem;
using eamos_test::read_json;
using eamos_test::read_text;

using eamos_test::Output;
Output eamos(const std::string& args, const std::function<void(const std::string&)>& on_line = {}) {
  return eamos_test::run_eamos(args, on_line);
}

std::string source(const std::string& name) { return std::string(EAMOS_SOURCE_DIR) + "/examples/" + name; }

struct Event {
  double t;
  std::string what;  ///< event, text, outcome, value
};
using Events = std::map<std::string, std::vector<Event>>;

/// Per drone, its events in order.
Events per_drone(const fs::path& trace) {
  Events events;
  std::ifstream in(trace);
  for (std::string line; std::getline(in, line);) {
    nlohmann::json e = nlohmann::json::parse(line);
    // The header, telemetry samples and messages differ by design between in-process and
    // distributed runs (sampling times, the ground's view): the execution events must not.
    std::string kind = e["event"].get<std::string>();
    if (kind == "header" || kind == "telemetry" || kind == "message") continue;
    std::string what = e["event"].get<std::string>() + " " + e.value("text", e["name"].get<std::string>()) + " " +
                       e.value("outcome", "");
    if (e.contains("value")) what += " " + e["value"].dump();
    events[e["drone"]].push_back({e["t"].get<double>(), what});
  }
  return events;
}

/// "" when every drone has the same events in the same order in both traces; otherwise
/// where they part. Events that `dist` records at one and the same instant on one drone
/// have no order among themselves (a Do's cancel and another drone's trigger can land in
/// the same step), so such a group only has to hold the same events.
std::string order_difference(const Events& local, const Events& dist) {
  if (local.size() != dist.size()) return "different drones";
  for (const auto& [drone, a] : local) {
    auto it = dist.find(drone);
    if (it == dist.end()) return drone + " missing";
    const std::vector<Event>& b = it->second;
    if (a.size() != b.size())
      return drone + ": " + std::to_string(a.size()) + " events in-process, " + std::to_string(b.size()) + " distributed";
    for (std::size_t i = 0; i < b.size();) {
      std::size_t j = i + 1;
      while (j < b.size() && b[j].t == b[i].t) ++j;
      std::vector<std::string> x, y;
      for (std::size_t k = i; k < j; ++k) x.push_back(a[k].what), y.push_back(b[k].what);
      std::sort(x.begin(), x.end());
      std::sort(y.begin(), y.end());
      if (x != y) return drone + ": event " + std::to_string(i) + " is '" + a[i].what + "' in-process, '" + b[i].what + "' distributed";
      i = j;
    }
  }
  return "";
}

/// What breaks the trace schema in `trace`, one line per fault; "" when nothing does.
std::string schema_errors(const fs::path& trace) {
  std::ifstream in(trace);
  std::string all;
  for (const std::string& e : eamos::trace::check_trace(in, {.strict = true})) all += e + "\n";
  return all;
}

nlohmann::json last_event(const fs::path& trace) {
  std::ifstream in(trace);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last.empty() ? nlohmann::json::object() : nlohmann::json::parse(last);
}

class Distributed : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eamos-dist-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  /// Flies `mission` in-process and as processes; expects the same events per drone.
  void expect_same_as_in_process(const std::string& mission, const std::string& fleet, int domain) {
    expect_same_as_in_process_at(source(mission), fleet, domain);
  }
  void expect_same_as_in_process_at(const std::string& mission_path, const std::string& fleet, int domain) {
    std::string fleet_arg = fleet.empty() ? "" : " --fleet " + source(fleet);
    Output local = eamos("run -q " + mission_path + fleet_arg + " --trace " + (dir_ / "local.jsonl").string());
    ASSERT_EQ(local.status, 0) << local.out;
    Output dist = eamos("run -q " + mission_path + fleet_arg + " --distributed --speed 5 --domain " +
                        std::to_string(domain) + " --deploy-dir " + (dir_ / "deploy").string() + " --trace " +
                        (dir_ / "dist.jsonl").string() + " --summary " + (dir_ / "summary.json").string());
    ASSERT_EQ(dist.status, 0) << dist.out;
    EXPECT_NE(dist.out.find("every drone is ready; starting run"), std::string::npos) << dist.out;
    // Each DEX's CPU time and peak memory as it exits (docs/performance.md reads them).
    EXPECT_NE(dist.out.find("exited with status 0 ("), std::string::npos) << dist.out;
    EXPECT_NE(dist.out.find(" CPU-s, peak RSS "), std::string::npos) << dist.out;
    // Both traces keep the schema (docs/trace.md), whichever way the mission ran.
    EXPECT_EQ(schema_errors(dir_ / "local.jsonl"), "");
    EXPECT_EQ(schema_errors(dir_ / "dist.jsonl"), "");
    Events a = per_drone(dir_ / "local.jsonl"), b = per_drone(dir_ / "dist.jsonl");
    EXPECT_FALSE(a.empty());
    EXPECT_EQ(order_difference(a, b), "") << dist.out;
    nlohmann::json summary = read_json(dir_ / "summary.json");
    EXPECT_EQ(summary["status"], "completed");
    // Both traces end with the mission's end, the distributed one at the reported duration.
    for (const char* trace : {"local.jsonl", "dist.jsonl"}) {
      nlohmann::json last = last_event(dir_ / trace);
      EXPECT_EQ(last["event"], "mission") << trace;
      EXPECT_EQ(last["outcome"], "completed") << trace;
    }
    // (trace times are rounded to the microsecond)
    EXPECT_NEAR(last_event(dir_ / "dist.jsonl")["t"].get<double>(), summary["duration"].get<double>(), 1e-6);
  }
  fs::path dir_;
};

TEST_F(Distributed, Listing2RightGivesTheSameEventsPerDroneAsInProcess) {
  expect_same_as_in_process("listing2.eamos", "listing2-right.yaml", 21);
}

TEST_F(Distributed, Listing2LeftGivesTheSameEventsPerDroneAsInProcess) {
  expect_same_as_in_process("listing2.eamos", "listing2-left.yaml", 22);
}

TEST_F(Distributed, SurveyGivesTheSameEventsPerDroneAsInProcess) { expect_same_as_in_process("survey.eamos", "", 23); }

TEST_F(Distributed, RelayGivesTheSameEventsPerDroneAsInProcess) { expect_same_as_in_process("relay.eamos", "", 24); }

TEST_F(Distributed, PatrolGivesTheSameEventsPerDroneAsInProcess) { expect_same_as_in_process("patrol.eamos", "", 25); }

TEST_F(Distributed, AFleetOfOneCompletesAsInProcess) {
  expect_same_as_in_process_at(std::string(EAMOS_SOURCE_DIR) + "/tests/launch/missions/one_drone.eamos", "", 206);
}

TEST_F(Distributed, TwentyDronesAndTheGroundFitOnOneHost) {
  // 21 participants on loopback: more than Cyclone's default of 9 automatic participant
  // indices, which the shipped configuration raises.
  std::string mission = (dir_ / "stress.eamos").string();
  Output g = eamos("gen-stress --nodes 500 --drones 20 -o " + mission);
  ASSERT_EQ(g.status, 0) << g.out;
  expect_same_as_in_process_at(mission, "", 31);
}

/// Compiles Listing 2 into dir/deploy.
fs::path deploy_listing2(const fs::path& dir) {
  Output c = eamos("compile -q " + source("listing2.eamos") + " -o " + (dir / "deploy").string());
  EXPECT_EQ(c.status, 0) << c.out;
  return dir / "deploy";
}

/// The pid the ground printed for `drone`'s DEX, or -1.
pid_t dex_pid(const std::string& out, const std::string& drone) {
  std::string key = "started the DEX of " + drone + " (pid ";
  auto at = out.find(key);
  return at == std::string::npos ? -1 : std::stoi(out.substr(at + key.size()));
}

TEST_F(Distributed, KilledDexPutsEveryOtherDroneInFailsafeWithinTheLivelinessTimeout) {
  fs::path deploy = deploy_listing2(dir_);
  // Speed 5: one wall second is five mission seconds. Drone2 is killed right after its
  // takeoff, while Drone1 and Drone3 are still flying.
  const double speed = 5.0, lease = 1.0;
  double killed_at = -1;
  Output r = eamos("launch " + deploy.string() + " --speed 5 --liveliness-timeout 1 --domain 26 --trace " +
                       (dir_ / "trace.jsonl").string() + " --summary " + (dir_ / "summary.json").string(),
                   [&](const std::string& line) {
                     static std::string seen;
                     seen += line;
                     if (killed_at < 0 && line.find("Drone2.Takeoff(10)  succeeded") != std::string::npos) {
                       pid_t pid = dex_pid(seen, "Drone2");
                       ASSERT_GT(pid, 0) << seen;
                       kill(pid, SIGKILL);
                       killed_at = std::stod(line);  // the event's mission time, printed first
                     }
                   });
  ASSERT_GT(killed_at, 0) << r.out;
  EXPECT_EQ(r.status, 1) << r.out;
  nlohmann::json summary = read_json(dir_ / "summary.json");
  EXPECT_EQ(summary["status"], "failed");
  EXPECT_NE(summary["error"].get<std::string>().find("Drone2 lost"), std::string::npos) << summary.dump(2);
  // Every drone still alive entered its failsafe, within the lease plus one wall second for
  // the kill to land and the lease check to run (seen here: 1.02 s after the kill in all).
  std::map<std::string, double> failsafe_at;
  std::ifstream in(dir_ / "trace.jsonl");
  for (std::string line; std::getline(in, line);) {
    nlohmann::json e = nlohmann::json::parse(line);
    if (e["event"] == "failsafe") failsafe_at[e["drone"]] = e["t"];
  }
  for (std::string drone : {"Drone1", "Drone3"}) {
    ASSERT_TRUE(failsafe_at.count(drone)) << drone << "\n" << r.out;
    EXPECT_LE(failsafe_at[drone] - killed_at, (lease + 1.0) * speed) << drone;
  }
  EXPECT_FALSE(failsafe_at.count("Drone2"));  // dead: it cannot report
  for (std::string drone : {"Drone1", "Drone3"}) {
    EXPECT_TRUE(summary["drones"][drone]["landed"]) << drone;
    EXPECT_FALSE(summary["drones"][drone]["armed"]) << drone;
  }
}

TEST_F(Distributed, RestartedDexDoesNotResumeTheAbandonedMission) {
  fs::path deploy = deploy_listing2(dir_);
  Output restarted;
  Output r = eamos("launch " + deploy.string() + " --speed 5 --liveliness-timeout 1 --domain 27",
                   [&](const std::string& line) {
                     static std::string seen;
                     seen += line;
                     if (restarted.status < 0 && line.find("Drone2.Takeoff(10)  succeeded") != std::string::npos) {
                       kill(dex_pid(seen, "Drone2"), SIGKILL);
                       // Started again at once, while the others still run (or abandon) the mission.
                       restarted = eamos("dex " + (deploy / "Drone2").string() +
                                         " --speed 5 --liveliness-timeout 1 --domain 27 --start-timeout 3");
                     }
                   });
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("Drone2 lost"), std::string::npos) << r.out;  // the others gave up on the old process
  EXPECT_EQ(restarted.status, 1) << restarted.out;
  EXPECT_NE(restarted.out.find("not joining run"), std::string::npos) << restarted.out;
  EXPECT_EQ(restarted.out.find("Drone2   start"), std::string::npos) << restarted.out;  // ran nothing
  EXPECT_NE(restarted.out.find("no start within 3 s"), std::string::npos) << restarted.out;
}

TEST_F(Distributed, StartBarrierTimeoutAbortsWithTheMissingDrones) {
  fs::path deploy = deploy_listing2(dir_);
  Output r = eamos("launch " + deploy.string() + " --drones Drone1 --barrier-timeout 1 --domain 28");
  EXPECT_EQ(r.status, 1) << r.out;
  // Drone1's DEX runs but is not ready either: a DEX is ready only once it has heard from
  // every other drone (a channel that never came up must not be found out mid-mission).
  EXPECT_NE(r.out.find("start barrier timed out after 1 s; not ready: Drone1, Drone2, Drone3"), std::string::npos)
      << r.out;
  std::string log = read_text(deploy / "Drone1" / "dex.log");
  EXPECT_NE(log.find("waiting for its peers"), std::string::npos) << log;
  EXPECT_EQ(log.find("Drone1   start"), std::string::npos) << log;  // nothing flew
}

// A fleet started all at once floods every participant with discovery and DDS Security
// handshakes at the same instant (thirty secure DEXes on a 2-core host were not ready in
// 85 s). In waves, a DEX starts only once the ground has heard from every one before it and
// they from each other (their handshakes done).
TEST_F(Distributed, AFleetStartedInWavesStartsEachWaveOnceTheGroundHeardTheOnesBefore) {
  fs::path deploy = deploy_listing2(dir_);
  Output r = eamos("launch " + deploy.string() + " --start-wave 1 --speed 5 --domain 42");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("starting 3 DEX processes in waves of 1"), std::string::npos) << r.out;
  auto at = [&](const std::string& s) { return r.out.find(s); };
  std::size_t first = at("started the DEX of Drone1"), heard1 = at("the 1 DEX processes started so far have heard from each other"),
              second = at("started the DEX of Drone2"), heard2 = at("the 2 DEX processes started so far have heard from each other"),
              third = at("started the DEX of Drone3");
  ASSERT_NE(third, std::string::npos) << r.out;
  EXPECT_LT(first, heard1) << r.out;
  EXPECT_LT(heard1, second) << r.out;
  EXPECT_LT(second, heard2) << r.out;
  EXPECT_LT(heard2, third) << r.out;
  EXPECT_NE(at("every drone is ready; starting run"), std::string::npos) << r.out;
}

// A large fleet's DEXes publish their drones' states less often (--state-rate): each state
// still gets out, the newest at the end of the period, and the mission completes. A timer
// that found itself a rounding short of the period's end once set itself again for the
// same instant for ever, and the DEX's loop never went past its first takeoff.
TEST_F(Distributed, ADexPublishesItsDronesStateAtMostAtItsStateRate) {
  fs::path deploy = deploy_listing2(dir_);
  Output r = eamos("launch " + deploy.string() + " --state-rate 2 --speed 5 --domain 43 --trace " +
                   (dir_ / "t.jsonl").string() + " --summary " + (dir_ / "summary.json").string());
  ASSERT_EQ(r.status, 0) << r.out;
  nlohmann::json summary = read_json(dir_ / "summary.json");
  double duration = summary["duration"].get<double>();
  // At 2 states a wall second and 5 mission seconds per wall second: one per 2.5 mission s
  // (the trace itself samples at 5 Hz, which every change at 20 Hz would fill).
  std::map<std::string, int> samples;
  std::ifstream in(dir_ / "t.jsonl");
  for (std::string line; std::getline(in, line);) {
    nlohmann::json e = nlohmann::json::parse(line);
    if (e["event"] == "telemetry") ++samples[e["drone"].get<std::string>()];
  }
  ASSERT_EQ(samples.size(), 3u) << r.out;
  for (const auto& [drone, n] : samples) {
    EXPECT_GE(n, 2) << drone;
    EXPECT_LE(n, duration / 2.5 + 2) << drone;
  }
}

// Debian 12's Cyclone DDS can crash when it gives up a DDS Security handshake (100 s; 50
// secure DEXes on one 2-core host got there and one died with SIGSEGV): nothing of eamos
// may wait that long with a handshake pending.
TEST_F(Distributed, ASecureBarrierLongerThanCycloneWaitsForAHandshakeIsRefusedBeforeAnyDexStarts) {
  fs::path deploy = deploy_listing2(dir_);
  Output r = eamos("launch " + deploy.string() + " --barrier-timeout 120 --domain 36");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("--barrier-timeout 120 is longer than DDS Security allows"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("use --barrier-timeout 85 or less"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("started the DEX"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(deploy / "Drone1" / "dex.log"));
}

TEST_F(Distributed, ASecureDexNotReadyWithinItsReadyTimeoutLeavesNamingTheDronesItNeverHeard) {
  fs::path deploy = deploy_listing2(dir_);
  Output r = eamos("dex " + (deploy / "Drone1").string() + " --ready-timeout 1 --domain 37");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("Drone1: not ready 1 s after joining DDS: nothing heard from Drone2, Drone3"),
            std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("Drone1   start"), std::string::npos) << r.out;  // nothing flew
  Output longer = eamos("dex " + (deploy / "Drone1").string() + " --ready-timeout 95 --domain 37");
  EXPECT_EQ(longer.status, 1) << longer.out;
  EXPECT_NE(longer.out.find("'95' is not a number from"), std::string::npos) << longer.out;
}

// Each wave has the whole start barrier from its own start (a handshake begins only when
// the later of its two DEXes starts): the barrier that runs out is the last wave's, and the
// ground says so. Drone3's DEX is started by no one here.
TEST_F(Distributed, TheStartBarrierOfAFleetStartedInWavesCountsFromTheLastWave) {
  fs::path deploy = deploy_listing2(dir_);
  Output r = eamos("launch " + deploy.string() +
                   " --drones Drone1,Drone2 --start-wave 1 --barrier-timeout 5 --insecure --domain 44");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("the 1 DEX processes started so far have heard from each other"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("start barrier timed out after 5 s of the wave started "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("after the first DEX (2 DEX processes started); not ready: Drone1, Drone2, Drone3"),
            std::string::npos) << r.out;
}

// `eamos launch` starts a large fleet in waves, and a DEX of an early wave may wait longer
// than its ready timeout for the later ones: a handshake begins only when the later of its
// two DEXes joins, whose own ready timeout bounds it. Drones it is told start later are not
// waited for; the others still are.
TEST_F(Distributed, ADexDoesNotLeaveUnreadyForDronesThatStartInALaterWave) {
  fs::path deploy = deploy_listing2(dir_);
  Output r = eamos("dex " + (deploy / "Drone1").string() + " --ready-timeout 1 --later-drones Drone3 --domain 37");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("Drone1: not ready 1 s after joining DDS: nothing heard from Drone2 ("), std::string::npos)
      << r.out;
  Output later = eamos("dex " + (deploy / "Drone1").string() +
                       " --ready-timeout 1 --later-drones Drone2,Drone3 --start-timeout 3 --domain 37");
  EXPECT_EQ(later.status, 1) << later.out;
  EXPECT_EQ(later.out.find("not ready"), std::string::npos) << later.out;
  EXPECT_NE(later.out.find("Drone1: no start within 3 s"), std::string::npos) << later.out;
  Output unknown = eamos("dex " + (deploy / "Drone1").string() + " --later-drones Drone9 --domain 37");
  EXPECT_EQ(unknown.status, 1) << unknown.out;
  EXPECT_NE(unknown.out.find("--later-drones names 'Drone9', which is not a drone of this mission"),
            std::string::npos) << unknown.out;
}

TEST_F(Distributed, SecondMissionOnTheSameDomainChangesNothing) {
  // Listing 2 and patrol at the same time on one domain: both have a Drone1..Drone3.
  Output other;
  fs::path patrol_dir = dir_ / "patrol";
  fs::create_directories(patrol_dir);
  Output local = eamos("run -q " + source("listing2.eamos") + " --trace " + (dir_ / "local.jsonl").string());
  ASSERT_EQ(local.status, 0);
  Output patrol_local = eamos("run -q " + source("patrol.eamos") + " --trace " + (patrol_dir / "local.jsonl").string());
  ASSERT_EQ(patrol_local.status, 0);
  std::string patrol_cmd = std::string(EAMOS_BINARY) + " run -q " + source("patrol.eamos") +
                           " --distributed --speed 5 --domain 29 --deploy-dir " + (patrol_dir / "deploy").string() +
                           " --trace " + (patrol_dir / "dist.jsonl").string() + " > " +
                           (patrol_dir / "out.txt").string() + " 2>&1";
  FILE* patrol = popen(patrol_cmd.c_str(), "r");
  Output r = eamos("run -q " + source("listing2.eamos") + " --distributed --speed 5 --domain 29 --deploy-dir " +
                   (dir_ / "deploy").string() + " --trace " + (dir_ / "dist.jsonl").string());
  int patrol_status = pclose(patrol);
  ASSERT_EQ(r.status, 0) << r.out;
  ASSERT_TRUE(WIFEXITED(patrol_status) && WEXITSTATUS(patrol_status) == 0) << read_text(patrol_dir / "out.txt");
  EXPECT_EQ(order_difference(per_drone(dir_ / "local.jsonl"), per_drone(dir_ / "dist.jsonl")), "");
  EXPECT_EQ(order_difference(per_drone(patrol_dir / "local.jsonl"), per_drone(patrol_dir / "dist.jsonl")), "");
  // They never met: each mission reads only its own partitions (and trusts only its own
  // CAs), so no sample of the other reached a DEX to be ignored there.
  std::string logs = r.out + read_text(patrol_dir / "out.txt");
  for (const char* d : {"Drone1", "Drone2", "Drone3"}) logs += read_text(dir_ / "deploy" / d / "dex.log");
  EXPECT_EQ(logs.find("ignoring messages of another mission"), std::string::npos) << logs;
  EXPECT_EQ(logs.find("ignored a"), std::string::npos) << logs;
}

/// Starts `eamos args` in the background with its output in `log`; returns its pid.
pid_t eamos_background(const std::string& args, const fs::path& log) {
  std::string cmd = std::string(EAMOS_BINARY) + " " + args + " > " + log.string() + " 2>&1 & echo $!";
  FILE* p = popen(cmd.c_str(), "r");
  char buf[64] = {0};
  if (!fgets(buf, sizeof buf, p)) buf[0] = '\0';
  pclose(p);
  return static_cast<pid_t>(std::atoi(buf));
}

TEST_F(Distributed, GroundEndsWhenADexStartedElsewhereIsLost) {
  fs::path deploy = deploy_listing2(dir_);
  // Drone2's DEX runs "on the drone": not started by the ground.
  pid_t remote = eamos_background("dex " + (deploy / "Drone2").string() +
                                      " --speed 5 --liveliness-timeout 1 --domain 32 --start-timeout 30",
                                  dir_ / "drone2.log");
  ASSERT_GT(remote, 0);
  bool killed = false;
  // A ground that waited for Drone2's final status would run into ctest's timeout (120 s).
  Output r = eamos("launch " + deploy.string() + " --drones Drone1,Drone3 --speed 5 --liveliness-timeout 1 " +
                       "--final-state-timeout 1 --domain 32 --summary " + (dir_ / "summary.json").string(),
                   [&](const std::string& line) {
                     if (!killed && line.find("Drone3.Takeoff(3)  succeeded") != std::string::npos) {
                       kill(remote, SIGKILL);
                       killed = true;
                     }
                   });
  ASSERT_TRUE(killed) << r.out;
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("Drone2 lost"), std::string::npos) << r.out;
  nlohmann::json summary = read_json(dir_ / "summary.json");
  EXPECT_EQ(summary["status"], "failed");
  // Its final state is unknown; it was last seen airborne, not as a drone that landed at home.
  EXPECT_EQ(summary["drones"]["Drone2"]["state"], "unknown") << summary.dump(2);
  EXPECT_FALSE(summary["drones"]["Drone2"]["last_seen"]["landed"]) << summary.dump(2);
}

TEST_F(Distributed, FailedActionOnOneDroneFailsTheMissionOnEveryDrone) {
  std::string mission = std::string(EAMOS_SOURCE_DIR) + "/tests/launch/missions/refused_takeoff.eamos";
  Output r = eamos("run -q " + mission + " --distributed --speed 5 --domain 33 --deploy-dir " +
                   (dir_ / "deploy").string() + " --trace " + (dir_ / "trace.jsonl").string() + " --summary " +
                   (dir_ / "summary.json").string());
  EXPECT_EQ(r.status, 1) << r.out;
  nlohmann::json summary = read_json(dir_ / "summary.json");
  EXPECT_EQ(summary["status"], "failed");
  ASSERT_TRUE(summary.contains("failure")) << summary.dump(2);
  EXPECT_EQ(summary["failure"]["drone"], "Late");
  EXPECT_EQ(summary["failure"]["action"], "Takeoff");
  EXPECT_EQ(summary["failure"]["line"], 23);
  EXPECT_EQ(summary["failure"]["kind"], "refused");  // carried by the ABORT across processes
  EXPECT_NE(summary["error"].get<std::string>().find("arm before Takeoff"), std::string::npos);
  // Lead, in the air on another process, got the ABORT and landed.
  std::string trace = read_text(dir_ / "trace.jsonl");
  EXPECT_NE(trace.find("\"drone\":\"Lead\",\"event\":\"failsafe\""), std::string::npos) << trace;
  nlohmann::json last = last_event(dir_ / "trace.jsonl");
  EXPECT_EQ(last["event"], "mission") << trace;
  EXPECT_EQ(last["outcome"], "failed");
  EXPECT_EQ(last["reason"], summary["error"]);
  EXPECT_NEAR(last["t"].get<double>(), summary["duration"].get<double>(), 1e-6);  // trace: to the µs
  EXPECT_TRUE(summary["drones"]["Lead"]["landed"]);
  EXPECT_FALSE(summary["drones"]["Lead"]["armed"]);
}

// Lead's failsafe is `hover`: the action it runs when Late's ABORT arrives (its Takeoff, or
// its Hover if the ABORT comes late) is cancelled, and that end is in the trace as with
// `land`, after the failsafe; the DEX then reports Lead hovering (DDS domain 204).
TEST_F(Distributed, ActionCancelledByAHoveringFailsafeHasItsEndInTheTrace) {
  std::string missions = std::string(EAMOS_SOURCE_DIR) + "/tests/launch/missions/";
  Output r = eamos("run -q " + missions + "refused_takeoff.eamos --fleet " + missions +
                   "hover_failsafe.yaml --distributed --insecure --speed 5 --domain 204 --deploy-dir " +
                   (dir_ / "deploy").string() + " --trace " + (dir_ / "trace.jsonl").string() + " --summary " +
                   (dir_ / "summary.json").string());
  EXPECT_EQ(r.status, 1) << r.out;
  std::string running;  // Lead's action started and not ended
  bool failsafe = false, cancelled_after_failsafe = false;
  for (const nlohmann::json& e : eamos_test::read_trace(dir_ / "trace.jsonl")) {
    if (e.value("drone", "") != "Lead") continue;
    std::string event = e["event"];
    if (event == "start") running = e["text"];
    if (event == "failsafe") failsafe = e["name"] == "hover";
    if (event == "end" && e["text"] == running) {
      cancelled_after_failsafe = failsafe && e["outcome"] == "cancelled";
      running.clear();
    }
  }
  EXPECT_TRUE(failsafe) << read_text(dir_ / "trace.jsonl");
  EXPECT_TRUE(cancelled_after_failsafe) << "Lead's " << running << " never ended\n" << read_text(dir_ / "trace.jsonl");
  nlohmann::json summary = read_json(dir_ / "summary.json");
  EXPECT_FALSE(summary["drones"]["Lead"]["landed"]) << summary.dump(2);  // hovering, as told
}

// The ground writes the merged trace once the mission is over: a write that fails (a full
// disk) is said and makes the exit status 1 although the mission completed (domain 205).
TEST_F(Distributed, TraceOnAFullDiskIsReportedAndTheExitStatusIsNonZero) {
  Output r = eamos("run -q " + std::string(EAMOS_SOURCE_DIR) + "/tests/launch/missions/hops.eamos --distributed "
                   "--insecure --speed 10 --domain 205 --deploy-dir " + (dir_ / "deploy").string() +
                   " --trace /dev/full --summary " + (dir_ / "summary.json").string());
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("eamos: error: cannot write the trace '/dev/full' (No space left on device)"),
            std::string::npos) << r.out;
  EXPECT_EQ(read_json(dir_ / "summary.json")["status"], "completed");
}

TEST_F(Distributed, TimeLimitFailsTheMissionOnEveryDrone) {
  Output r = eamos("run -q " + source("listing2.eamos") + " --distributed --speed 5 --time-limit 3 --domain 34 " +
                   "--deploy-dir " + (dir_ / "deploy").string() + " --summary " + (dir_ / "summary.json").string());
  EXPECT_EQ(r.status, 1) << r.out;
  nlohmann::json summary = read_json(dir_ / "summary.json");
  EXPECT_NE(summary["error"].get<std::string>().find("did not complete within 3"), std::string::npos) << summary.dump(2);
  for (const char* d : {"Drone1", "Drone2", "Drone3"}) EXPECT_TRUE(summary["drones"][d]["landed"]) << d;
}

// A mission file whose loop takes no time (made by hand here: `eamos check` refuses the
// source): the DEX must neither hang nor starve its liveliness; it fails the mission, lands,
// and the ground reports it, all well within the time limit.
TEST_F(Distributed, LoopThatTakesNoTimeFailsTheMissionInsteadOfHangingTheDex) {
  fs::path deploy = dir_ / "deploy";
  Output c = eamos("compile -q " + std::string(EAMOS_SOURCE_DIR) + "/tests/dex/missions/zero_time_loop.eamos -o " +
                   deploy.string());
  ASSERT_EQ(c.status, 0) << c.out;
  fs::path file = deploy / "Drone1" / "mission.json";
  nlohmann::json m = read_json(file);
  int changed = 0;
  for (auto& n : m["nodes"])
    if (n.value("text", "") == "Drone1.TakePicture()") n["kind"] = "fork", ++changed;
  ASSERT_EQ(changed, 1);
  std::ofstream(file) << eamos_test::sealed(m);  // re-sealed: the reader refuses a stale hash
  Output r = eamos("launch " + deploy.string() + " --speed 5 --time-limit 20 --domain 41 --trace " +
                   (dir_ / "trace.jsonl").string() + " --summary " + (dir_ / "summary.json").string());
  EXPECT_EQ(r.status, 1) << r.out;
  nlohmann::json summary = read_json(dir_ / "summary.json");
  EXPECT_EQ(summary["status"], "failed");
  EXPECT_NE(summary["error"].get<std::string>().find("RepeatWhile (line 5) failed: 10000 iterations in a row took "
                                                     "no mission time"),
            std::string::npos)
      << summary.dump(2);
  EXPECT_LT(summary["duration"].get<double>(), 20.0);
  EXPECT_TRUE(summary["drones"]["Drone1"]["landed"]);
  EXPECT_FALSE(summary["drones"]["Drone1"]["armed"]);
  nlohmann::json last = last_event(dir_ / "trace.jsonl");
  EXPECT_EQ(last["event"], "mission");
  EXPECT_EQ(last["outcome"], "failed");
}

TEST_F(Distributed, SpeedMismatchAbortsBeforeAnyDroneMoves) {
  fs::path deploy = deploy_listing2(dir_);
  pid_t remote = eamos_background("dex " + (deploy / "Drone2").string() + " --speed 1 --domain 35 --start-timeout 30",
                                  dir_ / "drone2.log");
  ASSERT_GT(remote, 0);
  Output r = eamos("launch " + deploy.string() + " --drones Drone1,Drone3 --speed 5 --domain 35");
  EXPECT_EQ(r.status, 1) << r.out;
  // Refused at the start barrier, from the speeds in the READYs: no START, so nothing depends
  // on an ABORT reaching Drone1 and Drone3 before a start instant.
  EXPECT_NE(r.out.find("a DEX runs at another speed than the ground (--speed 5): Drone2 at 1; nothing was armed"),
            std::string::npos)
      << r.out;
  for (const char* d : {"Drone1", "Drone3"}) {
    std::string log = read_text(deploy / d / "dex.log");
    EXPECT_EQ(log.find(std::string(d) + "   start"), std::string::npos) << log;  // nothing moved
  }
  // Drone2's DEX, not a child of this test, ends on the ground's barrier ABORT.
  for (auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
       kill(remote, 0) == 0 && std::chrono::steady_clock::now() < until;)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_NE(kill(remote, 0), 0) << "Drone2's DEX still runs 30 s after the launch refused to start";
  std::string remote_log = read_text(dir_ / "drone2.log");
  EXPECT_NE(remote_log.find("the ground gave up before the start"), std::string::npos) << remote_log;
  EXPECT_NE(remote_log.find("start it with --speed 5"), std::string::npos) << remote_log;
  EXPECT_EQ(remote_log.find("Drone2   start"), std::string::npos) << remote_log;
}

/// Launches long_hover.eamos on `domain` and, once both drones are airborne, writes an
/// ABORT of the running run from this test process, as `sender` with `reason`: what an
/// outside (buggy or hostile) participant on the domain could send.
/// Launches long_hover.eamos and, once both drones are airborne, writes an ABORT from a
/// participant of the test's own; with `then_valid`, a well-formed ABORT from the ground
/// follows it, so a test can show that the first was dropped and the DEXes still obey.
Output launch_and_abort_from_outside(const fs::path& dir, int domain, int sender, const std::string& reason,
                                     bool then_valid = false) {
  std::string mission = std::string(EAMOS_SOURCE_DIR) + "/tests/launch/missions/long_hover.eamos";
  // --insecure: these tests are about what every DEX checks of every sample it gets
  // (security_test.cpp shows that with DDS Security a stranger's sample does not arrive).
  Output c = eamos("compile -q --insecure " + mission + " -o " + (dir / "deploy").string());
  EXPECT_EQ(c.status, 0) << c.out;
  std::string hash = read_json(dir / "deploy" / "manifest.json")["mission_hash"];
  eamos::transport::DdsOptions dds;
  dds.domain = domain;
  dds.mission_hash = hash;
  dds.self = eamos::transport::kGround;  // writes in the ground's partition, as the ground would
  std::string error;
  std::unique_ptr<eamos::transport::DdsNode> node = eamos::transport::DdsNode::open(dds, {}, error);
  EXPECT_TRUE(node) << error;
  std::uint64_t run = 0;
  int airborne = 0;
  bool sent = false;
  Output r = eamos("launch " + (dir / "deploy").string() + " --insecure --speed 5 --domain " + std::to_string(domain) +
                       " --trace " + (dir / "trace.jsonl").string() + " --summary " + (dir / "summary.json").string(),
                   [&](const std::string& line) {
                     auto at = line.find("starting run ");
                     if (at != std::string::npos) run = std::stoull(line.substr(at + 13));
                     if (line.find(".Takeoff(5)  succeeded") != std::string::npos) ++airborne;
                     if (!sent && airborne == 2 && node) {
                       eamos::transport::LifecycleSample abort{hash, sender, eamos::transport::LifecycleKind::abort,
                                                               run};
                       abort.reason = reason;
                       EXPECT_TRUE(node->write(abort));
                       if (then_valid) {
                         eamos::transport::LifecycleSample valid{hash, eamos::transport::kGround,
                                                                 eamos::transport::LifecycleKind::abort, run};
                         valid.reason = "valid abort after the bad one";
                         EXPECT_TRUE(node->write(valid));
                       }
                       sent = true;
                     }
                   });
  EXPECT_TRUE(sent) << r.out;
  return r;
}

/// Expects every drone of long_hover.eamos to have run its failsafe and to be down.
void expect_every_drone_in_failsafe(const fs::path& dir, const Output& r) {
  EXPECT_EQ(r.status, 1) << r.out;
  std::string logs = r.out;
  for (const char* d : {"Lead", "Wing"}) logs += read_text(dir / "deploy" / d / "dex.log");
  for (const char* leak : {"json.exception", "_M_range_check", "terminate called", "what():"})
    EXPECT_EQ(logs.find(leak), std::string::npos) << leak << "\n" << logs;
  std::map<std::string, int> failsafes;
  std::ifstream in(dir / "trace.jsonl");
  for (std::string line; std::getline(in, line);) {
    nlohmann::json e = nlohmann::json::parse(line);
    if (e["event"] == "failsafe") ++failsafes[e["drone"]];
  }
  EXPECT_EQ(failsafes, (std::map<std::string, int>{{"Lead", 1}, {"Wing", 1}})) << logs;
  ASSERT_TRUE(fs::exists(dir / "summary.json")) << logs;
  nlohmann::json summary = read_json(dir / "summary.json");
  EXPECT_EQ(summary["status"], "failed");
  for (const char* d : {"Lead", "Wing"}) {
    EXPECT_TRUE(summary["drones"][d]["landed"]) << d << "\n" << summary.dump(2);
    EXPECT_FALSE(summary["drones"][d]["armed"]) << d << "\n" << summary.dump(2);
  }
}

// Text from outside that is not UTF-8 (here an ABORT's reason) would make the ground's JSON
// trace writer (nlohmann::json::dump) throw and lose the whole report. Such a sample is
// dropped where it arrives (from_wire) and logged; the DEXes go on and obey the valid ABORT
// that follows.
TEST_F(Distributed, AbortWithAReasonThatIsNotUtf8IsDroppedAndTheNextAbortIsObeyed) {
  Output r = launch_and_abort_from_outside(dir_, 36, eamos::transport::kGround, "stop \xff\xfe now", true);
  ASSERT_NO_FATAL_FAILURE(expect_every_drone_in_failsafe(dir_, r));
  EXPECT_NE(read_json(dir_ / "summary.json")["error"].get<std::string>().find("valid abort after the bad one"),
            std::string::npos);
  std::string log = read_text(dir_ / "deploy" / "Lead" / "dex.log");
  EXPECT_NE(log.find("dropped a lifecycle sample"), std::string::npos) << log;
}

// A sender number no drone of the mission has must not make a DEX throw (fleet.at) out of
// its event loop and exit with its drone in the air: the sample is dropped and logged where
// it arrives, and the DEXes still obey the valid ABORT after it.
TEST_F(Distributed, AbortFromAnUnknownDroneNumberIsDroppedAndTheNextAbortIsObeyed) {
  Output r = launch_and_abort_from_outside(dir_, 37, 7, "from nowhere", true);
  ASSERT_NO_FATAL_FAILURE(expect_every_drone_in_failsafe(dir_, r));
  std::string log = read_text(dir_ / "deploy" / "Lead" / "dex.log");
  EXPECT_NE(log.find("dropped a lifecycle sample"), std::string::npos) << log;
  EXPECT_EQ(log.find("from nowhere"), std::string::npos) << log;
  EXPECT_NE(log.find("valid abort after the bad one"), std::string::npos) << log;
}

// Lead's DEX gets `signal` once both drones are airborne; every drone must end in its
// failsafe, and Lead's DEX says why (it was not lost).
void signal_the_lead_dex_in_flight(const fs::path& dir, int signal, const std::string& name, int domain) {
  std::string mission = std::string(EAMOS_SOURCE_DIR) + "/tests/launch/missions/long_hover.eamos";
  Output c = eamos("compile -q " + mission + " -o " + (dir / "deploy").string());
  ASSERT_EQ(c.status, 0) << c.out;
  int airborne = 0;
  pid_t lead = -1;
  std::string seen;
  Output r = eamos("launch " + (dir / "deploy").string() + " --speed 5 --domain " + std::to_string(domain) +
                       " --trace " + (dir / "trace.jsonl").string() + " --summary " + (dir / "summary.json").string(),
                   [&](const std::string& line) {
                     seen += line;
                     if (line.find(".Takeoff(5)  succeeded") != std::string::npos && ++airborne == 2) {
                       lead = dex_pid(seen, "Lead");
                       ASSERT_GT(lead, 0) << seen;
                       kill(lead, signal);
                     }
                   });
  ASSERT_GT(lead, 0) << r.out;
  ASSERT_NO_FATAL_FAILURE(expect_every_drone_in_failsafe(dir, r));
  std::string log = read_text(dir / "deploy" / "Lead" / "dex.log");
  EXPECT_NE(log.find("Lead's DEX was interrupted (" + name + ")"), std::string::npos) << log;
  EXPECT_EQ(r.out.find("no liveliness"), std::string::npos) << r.out;  // it said why, it was not lost
}

// A DEX stopped with SIGTERM (its service stopped, a shutdown) must not die at once: the
// others would fail on its lost liveliness, its own drone would stay in the air.
TEST_F(Distributed, SigtermOnADexLandsItsDroneAndEveryOther) {
  signal_the_lead_dex_in_flight(dir_, SIGTERM, "SIGTERM", 38);
}

// A DEX started by hand in an SSH session that drops gets SIGHUP: the same as SIGTERM, not
// the default action that ended it with its drone in the air.
TEST_F(Distributed, HangupOfTheSessionADexWasStartedFromLandsItsDroneAndEveryOther) {
  signal_the_lead_dex_in_flight(dir_, SIGHUP, "SIGHUP", 39);
}

TEST_F(Distributed, DexRefusesAFolderWithoutAMission) {
  fs::create_directories(dir_ / "empty");
  Output r = eamos("dex " + (dir_ / "empty").string() + " --domain 30 --start-timeout 1");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("error:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mission.json"), std::string::npos) << r.out;
}

TEST_F(Distributed, LaunchRefusesAFolderWithoutAManifest) {
  Output r = eamos("launch " + dir_.string() + " --domain 30");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("manifest.json"), std::string::npos) << r.out;
}

}  // namespace
