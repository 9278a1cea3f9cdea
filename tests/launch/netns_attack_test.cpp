// Attacks and a frozen DEX on the namespace network of netns_test.cpp
// (docs/security.md "Attacks tried", docs/faults.md "A bad network"). The attacker is a
// process of its own, eamos-dds-attacker (tests/support/dds_attacker.cpp, the project's
// transport), in a fifth namespace joined to the mission's network only through the relay,
// as a machine on the drones' network would be. The mission (missions/hops_watch.eamos) is
// hops.eamos with one step on another drone's telemetry: C flies by A's x (to 0; a forged
// x = 50 sends it to 40). Expected: the mission completes with the in-process per-drone
// order and nothing forged is obeyed; with --insecure the attacker's samples do reach the
// DEXes (it reads the run's triggers and START) and the per-sample checks drop the invalid
// ones, while forged telemetry, which nothing can tell from real, is believed. A frozen
// DEX (SIGSTOP, then SIGCONT) in its namespace: longer than the lease, every drone is in
// its failsafe within the lease and the frozen one abandons when resumed; shorter, the
// mission completes. DDS domains 180-189. Needs root and `ip netns`; skipped
// with a message otherwise.
#include "netns_fixture.h"

namespace {

using namespace netns_support;

/// The mission time of the first `event` ("start", "end") of `drone`'s action `name` in
/// the ground's merged trace (-1: none).
double first(const fs::path& trace, const std::string& drone, const std::string& event, const std::string& name) {
  for (const nlohmann::json& e : read_trace(trace))
    if (e.value("drone", "") == drone && e.value("event", "") == event && e.value("name", "") == name) return e["t"];
  return -1;
}

/// The largest x drone `drone` reported in the ground's merged trace (-1e9: none).
double max_x(const fs::path& trace, const std::string& drone) {
  double x = -1e9;
  for (const nlohmann::json& e : read_trace(trace))
    if (e.value("event", "") == "telemetry" && e.value("drone", "") == drone) x = std::max(x, e["x"].get<double>());
  return x;
}

class NetnsAttack : public Netns {
 protected:
  NetnsAttack() {
    mission_ = "hops_watch.eamos";
    attacker_ = true;
  }
  std::string mission_hash(const fs::path& deploy) {
    return nlohmann::json::parse(read_text(deploy / "manifest.json"))["mission_hash"].get<std::string>();
  }
  /// Starts the attacker in its namespace (with `security`'s credentials, posing as
  /// drone `as`, when given); waits until its participants exist.
  void start_attacker(const std::string& security = "", int as = 0) {
    int k = attacker_namespace();
    std::vector<std::string> args = {"ip", "netns", "exec", ns_name(k), EAMOS_ATTACKER, "--domain",
                                     std::to_string(domain_), "--hash", mission_hash(dir_ / "deploy"), "--drones",
                                     std::to_string(kDrones.size()), "--dds-config", config(k).string()};
    if (!security.empty()) args.insert(args.end(), {"--security", security, "--as", std::to_string(as)});
    attacker_process_ = start(args, "", true);
    ASSERT_TRUE(read_until(attacker_process_, "ready")) << attacker_process_.seen;
  }
  void attack(const std::string& command) {
    fprintf(attacker_process_.in, "%s\n", command.c_str());
    fflush(attacker_process_.in);
  }
  /// Ends the attacker; everything it said (each command's "ok", what it read).
  std::string stop_attacker() {
    wait_exit(attacker_process_);
    return attacker_process_.seen;
  }

  /// Flies the mission while `at_start(run)` attacks when the ground starts run `run` and
  /// `before_c_reads_a(run)` once C is airborne (before C reads A's x); returns the
  /// ground's exit status.
  int fly_attacked(const std::string& extra, const std::function<void(const std::string&)>& at_start,
                   const std::function<void(const std::string&)>& before_c_reads_a) {
    std::string run;
    bool second = false;
    int status = fly(extra, [&](const std::string& line) {
      const std::string key = "starting run ";
      auto at = line.find(key);
      if (run.empty() && at != std::string::npos) {
        run = std::to_string(std::stoull(line.substr(at + key.size())));
        at_start(run);
      }
      if (!run.empty() && !second && line.find("C.Takeoff(5)  succeeded") != std::string::npos) {
        second = true;
        before_c_reads_a(run);
      }
    });
    if (attacker_process_.in) fclose(attacker_process_.in);
    attacker_process_.in = nullptr;
    EXPECT_FALSE(run.empty()) << ground_.seen;
    return status;
  }

  /// Completed in the in-process per-drone order, every DEX exited 0, C flew by A's real x
  /// and nobody mentions the attacker's reason.
  void expect_completed_unmoved(int status, const std::map<std::string, std::vector<std::string>>& reference) {
    ASSERT_EQ(status, 0) << logs();
    EXPECT_EQ(per_drone(dir_ / "trace.jsonl"), reference) << logs();
    for (int s : dex_status_) EXPECT_EQ(s, 0) << logs();
    double c_x = max_x(dir_ / "trace.jsonl", "C");
    std::cout << "C's largest x: " << c_x << " (A.X() forged as 50 would take it to 40)\n";
    EXPECT_LT(c_x, 5.0) << logs();
    EXPECT_EQ(logs().find("forged by the attacker"), std::string::npos) << logs();
    // No early takeoff: each drone armed only once the one before it was up.
    fs::path trace = dir_ / "trace.jsonl";
    EXPECT_GE(first(trace, "B", "start", "Arm"), first(trace, "A", "end", "Takeoff")) << logs();
    EXPECT_GE(first(trace, "C", "start", "Arm"), first(trace, "B", "end", "Takeoff")) << logs();
    // Nobody completed early: the run lasted until the last disarm (in process: 22.55 s).
    nlohmann::json summary = nlohmann::json::parse(read_text(dir_ / "summary.json"));
    EXPECT_EQ(summary["status"], "completed");
    EXPECT_GE(summary["duration"].get<double>(), first(trace, "A", "end", "Disarm")) << summary.dump(2);
    EXPECT_GT(summary["duration"].get<double>(), 20.0) << summary.dump(2);
  }

  /// What the secure runs send: every kind the attacker sent, valid-looking where
  /// it can be. B's nonce is the one of the newest START the attacker read, if any.
  void forge_everything(const std::string& run, const std::vector<int>& posing) {
    for (int d : posing) attack("finished " + run + " " + std::to_string(d));
    for (int d : posing) {
      std::string from = std::to_string(d);
      attack("abort " + run + " " + from + " " + from);         // an ABORT of a drone of the mission
      attack("abort " + run + " " + from + " 99");              // the drone index out of range
      attack("trigger " + run + " " + from + " 1 99999 1");     // a node that does not exist
      attack("status " + run + " " + from);                     // that drone busy, then silence
    }
    attack("trigger " + run + " 0 1 2 1");  // "A's takeoff ended" to B: B would take off at once
    attack("trigger " + run + " 1 2 4 1");  // "B's takeoff ended" to C
    attack("replay");
  }

  Child attacker_process_;
};

TEST_F(NetnsAttack, ProcessWithoutCredentialsIsNotObeyed) {
  domain_ = 180;
  auto reference = in_process_order();
  ASSERT_NO_FATAL_FAILURE(start_relay({}));
  ASSERT_NO_FATAL_FAILURE(start_attacker());
  int status = fly_attacked(
      "", [&](const std::string& run) { forge_everything(run, {0, 1, 2}); },
      [&](const std::string& run) { attack("telemetry " + run + " 0 50 1500"); });
  std::string attacker = stop_attacker();
  std::string figures = stop_relay();
  std::cout << figures << attacker;
  expect_completed_unmoved(status, reference);
  EXPECT_EQ(attacker.find("error"), std::string::npos) << attacker;  // everything was written
  EXPECT_NE(attacker.find("read: 0 triggers, 0 starts"), std::string::npos) << attacker;  // and nothing read
  EXPECT_NE(figures.find("link Attacker: forwarded"), std::string::npos) << figures;
  EXPECT_EQ(logs().find(": ignored a "), std::string::npos) << logs();  // nothing forged even arrived
}

TEST_F(NetnsAttack, ProcessWithAnotherCompilationsCredentialsIsNotObeyed) {
  // The same mission compiled again: same hash and partitions, valid permissions for them
  // as B, signed by other CAs. One set of credentials per process: it writes as B, in B's
  // partition, and claims to be A and C too.
  domain_ = 181;
  Output other = eamos_test::run_eamos("compile -q " + std::string(EAMOS_SOURCE_DIR) + "/tests/launch/missions/" +
                                       mission_ + " -o " + (dir_ / "other").string());
  ASSERT_EQ(other.status, 0) << other.out;
  ASSERT_EQ(mission_hash(dir_ / "other"), mission_hash(dir_ / "deploy"));
  auto reference = in_process_order();
  ASSERT_NO_FATAL_FAILURE(start_relay({}));
  ASSERT_NO_FATAL_FAILURE(start_attacker((dir_ / "other" / "B" / "security").string(), 1));
  int status = fly_attacked(
      "", [&](const std::string& run) { forge_everything(run, {0, 1, 2}); },
      [&](const std::string& run) { attack("telemetry " + run + " 0 50 1500"); });
  std::string attacker = stop_attacker();
  std::string figures = stop_relay();
  std::cout << figures << attacker;
  expect_completed_unmoved(status, reference);
  EXPECT_NE(attacker.find("read: 0 triggers, 0 starts"), std::string::npos) << attacker;
  EXPECT_NE(figures.find("link Attacker: forwarded"), std::string::npos) << figures;
  EXPECT_EQ(logs().find(": ignored a "), std::string::npos) << logs();
}

TEST_F(NetnsAttack, WithSecurityOffTheAttackReachesTheDexesAndTheChecksDropWhatIsInvalid) {
  // What the secure runs are measured against: with --insecure the attacker reads the
  // run (START, every trigger) and what it writes arrives. Only samples the per-sample
  // checks can tell from real ones are sent here (docs/security.md says what else
  // --insecure lets through): FINISHED from everyone early, ABORT from drone 99 and one
  // naming a drone not in the mission, a junk node, every trigger replayed.
  domain_ = 182;
  dex_extra_ = " --insecure";
  auto reference = in_process_order();
  ASSERT_NO_FATAL_FAILURE(start_relay({}));
  ASSERT_NO_FATAL_FAILURE(start_attacker());
  int status = fly_attacked(
      "--insecure",
      [&](const std::string& run) {
        for (int d : {0, 1, 2}) attack("finished " + run + " " + std::to_string(d));
        attack("abort " + run + " 1 99");
        attack("abort " + run + " 1 1 Drone99");
        attack("trigger " + run + " 0 1 99999 1");
        attack("replay");
      },
      [](const std::string&) {});
  std::string attacker = stop_attacker();
  std::string figures = stop_relay();
  std::cout << figures << attacker;
  expect_completed_unmoved(status, reference);
  EXPECT_EQ(attacker.find("read: 0 triggers"), std::string::npos) << attacker;  // it read the run
  EXPECT_EQ(attacker.find("replayed 0"), std::string::npos) << attacker;
  std::string all = logs();
  for (const char* why : {"ignored a finished sample from", "node 99999 of A is not in this drone's mission",
                          "was already received", "the failed drone it names is not in the mission",
                          "dropped a lifecycle sample"})
    EXPECT_NE(all.find(why), std::string::npos) << why << "\n" << all;
}

TEST_F(NetnsAttack, WithSecurityOffForgedTelemetryIsBelieved) {
  // What "C's largest x below 5" in the secure runs is measured against: the same flood
  // of A at x = 50, with --insecure, is taken for A's own telemetry. C acts on it one of two
  // ways: it flies by the forged x towards 40 and the mission completes, or its separation
  // guard, seeing A at 10 and at 50 by turns, holds it for the phantom A until the give-way
  // bound fails the mission over. Either is the forgery believed: in the secure runs C flies
  // by A's real x and gives way to nobody.
  domain_ = 185;
  dex_extra_ = " --insecure";
  ASSERT_NO_FATAL_FAILURE(start_relay({}));
  ASSERT_NO_FATAL_FAILURE(start_attacker());
  int status = fly_attacked(
      "--insecure", [](const std::string&) {},
      [&](const std::string& run) { attack("telemetry " + run + " 0 50 1500"); });
  stop_attacker();
  stop_relay();
  if (status != 0) {
    EXPECT_NE(logs().find("C gave way to A for 30.0 s"), std::string::npos) << logs();
    return;
  }
  double c_x = max_x(dir_ / "trace.jsonl", "C");
  std::cout << "C's largest x: " << c_x << "\n";
  EXPECT_GT(c_x, 30.0) << logs();
}

// --- a DEX frozen in its namespace (SIGSTOP, then SIGCONT) ---

TEST_F(Netns, DexFrozenLongerThanTheLeasePutsEveryDroneInItsFailsafeAndAbandonsWhenResumed) {
  // B's DEX is frozen after B's takeoff for 3 wall s (three leases; the shell's timer, as
  // a cut's is the relay's), while A and C give it up. The loopback version is
  // Faults.DexStalledLongerThanTheLease...
  domain_ = 183;
  ASSERT_NO_FATAL_FAILURE(start_relay({}));
  double stopped_at = -1;
  Child freezer;
  int status = fly("--final-state-timeout 5", [&](const std::string& line) {
    if (stopped_at < 0 && line.find("B.Takeoff(5)  succeeded") != std::string::npos) {
      // `ip netns exec` execs the DEX: the pid is the DEX's.
      std::string pid = std::to_string(dexes_[1].pid);
      freezer = start({"sh", "-c", "kill -STOP " + pid + " && sleep 3 && kill -CONT " + pid});
      stopped_at = std::stod(line);
    }
  });
  stop_relay();
  ASSERT_GT(freezer.pid, 0) << logs();
  EXPECT_EQ(wait_exit(freezer), 0) << freezer.seen;
  EXPECT_EQ(status, 1) << logs();
  std::map<std::string, double> at = failsafes();
  double lease = std::stod(lease_), speed = std::stod(speed_);
  for (std::string d : {"A", "C"}) {
    ASSERT_GE(at[d], 0) << d << "\n" << logs();
    EXPECT_LE(at[d] - stopped_at, (lease + 1.0) * speed) << d << "\n" << logs();
    std::cout << d << ": failsafe " << at[d] - stopped_at << " mission s after the freeze\n";
  }
  // Woken, B abandons at once: its loop saw the stall, or Cyclone's lease check (frozen
  // with it) reported the others lost first; either way before any overdue timer.
  std::string log = read_text(dir_ / "B.log");
  EXPECT_TRUE(log.find("B's DEX stalled for") != std::string::npos || log.find("lost: no liveliness") != std::string::npos)
      << log;
  for (const char* why : {"stalled for", "lost: no liveliness"})
    if (log.find(why) != std::string::npos) std::cout << "B: " << log.substr(log.find(why), 60) << "\n";
  ASSERT_GE(at["B"], 0) << logs();
  std::cout << "B: failsafe " << at["B"] - stopped_at << " mission s after the freeze (at its resume)\n";
  EXPECT_GE(at["B"] - stopped_at, lease * speed) << logs();  // not back-dated
  // Nothing of B's dated inside the freeze (a mission second after the stop for the signal
  // to land, up to its failsafe), no action started after it: nothing overdue was run.
  std::vector<std::string> replayed;
  for (const nlohmann::json& e : read_trace(dir_ / "B.jsonl")) {
    double t = e.value("t", 0.0);
    if (e.value("drone", "") != "B" || t <= stopped_at + 1.0) continue;
    if (t < at["B"] || e.value("event", "") == "start") replayed.push_back(e.dump());
  }
  EXPECT_TRUE(replayed.empty()) << replayed.front() << "\n" << logs();
  nlohmann::json summary = nlohmann::json::parse(read_text(dir_ / "summary.json"));
  for (const std::string& d : kDrones) {
    EXPECT_TRUE(summary["drones"][d]["landed"]) << d << summary.dump(2);
    EXPECT_FALSE(summary["drones"][d]["armed"]) << d << summary.dump(2);
  }
}

TEST_F(Netns, DexFrozenForLessThanTheLeaseCompletesInTheSameOrder) {
  // Frozen for 0.5 wall s (2.5 mission s at speed 5, while C's trigger to B arrives)
  // under a 2 s lease: nobody is lost, B goes on late. The freeze's length is the
  // shell's timer, as a cut's is the relay's.
  domain_ = 184;
  lease_ = "2";
  auto reference = in_process_order();
  ASSERT_NO_FATAL_FAILURE(start_relay({}));
  Child freezer;
  int status = fly("", [&](const std::string& line) {
    if (freezer.pid < 0 && line.find("B.Takeoff(5)  succeeded") != std::string::npos) {
      std::string pid = std::to_string(dexes_[1].pid);
      freezer = start({"sh", "-c", "kill -STOP " + pid + " && sleep 0.5 && kill -CONT " + pid});
    }
  });
  stop_relay();
  ASSERT_GT(freezer.pid, 0) << logs();
  EXPECT_EQ(wait_exit(freezer), 0) << freezer.seen;
  ASSERT_EQ(status, 0) << logs();
  EXPECT_EQ(per_drone(dir_ / "trace.jsonl"), reference) << logs();
  for (int s : dex_status_) EXPECT_EQ(s, 0) << logs();
  EXPECT_EQ(read_text(dir_ / "B.log").find("stalled"), std::string::npos) << logs();
}

}  // namespace
