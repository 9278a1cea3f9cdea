// Faults of the distributed run that must end safely and be reported truly: a DEX frozen
// longer than the liveliness lease, a ground stopped mid-run, a second launch of a running
// deployment. Real `eamos launch` / `eamos dex` processes on
// loopback, DDS domains 160-169; nothing here sleeps: the tests block on the processes'
// output (a frozen DEX is resumed when the ground reports it lost, not after a timer).
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/types.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/eamos_process.h"
#include "support/read_files.h"
#include "support/run_eamos.h"
#include "transport/dds_node.h"

namespace {

namespace fs = std::filesystem;
using eamos_test::read_text;
using eamos_test::read_json;
using eamos_test::read_trace;
using eamos_test::Output;

std::string example(const std::string& name) { return std::string(EAMOS_SOURCE_DIR) + "/examples/" + name; }
std::string test_mission(const std::string& name) {
  return std::string(EAMOS_SOURCE_DIR) + "/tests/launch/missions/" + name;
}

/// The pid the ground printed for `drone`'s DEX, or -1.
pid_t dex_pid(const std::string& out, const std::string& drone) {
  std::string key = "started the DEX of " + drone + " (pid ";
  auto at = out.find(key);
  return at == std::string::npos ? -1 : std::stoi(out.substr(at + key.size()));
}

class Faults : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eamos-faults-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  fs::path compile(const std::string& mission) {
    Output c = eamos_test::run_eamos("compile -q " + mission + " -o " + (dir_ / "deploy").string());
    EXPECT_EQ(c.status, 0) << c.out;
    return dir_ / "deploy";
  }
  fs::path dir_;
};

// Frozen (SIGSTOP) after its takeoff until the others have given it up and landed (their
// DEXes exited: over two wall seconds, twice the lease), then resumed: the DEX must not
// replay every timer that fell due meanwhile in milliseconds, starting its next actions
// with back-dated trace times before it hears of the ABORT. Its loop sees the stall, and
// the failsafe comes first, at the mission time of the resume.
TEST_F(Faults, DexStalledLongerThanTheLeaseAbandonsIntoItsFailsafeWithoutRunningOverdueActions) {
  fs::path deploy = compile(example("listing2.eamos"));
  const double speed = 5.0, lease = 1.0;
  pid_t drone2 = -1;
  double stopped_at = -1;
  bool resumed = false;
  int others_exited = 0;
  std::string seen;
  Output r = eamos_test::run_eamos(
      "launch " + deploy.string() + " --speed 5 --liveliness-timeout 1 --domain 160 --trace " +
          (dir_ / "trace.jsonl").string() + " --summary " + (dir_ / "summary.json").string(),
      [&](const std::string& line) {
        seen += line;
        if (drone2 < 0 && line.find("Drone2.Takeoff(10)  succeeded") != std::string::npos) {
          drone2 = dex_pid(seen, "Drone2");
          ASSERT_GT(drone2, 0) << seen;
          kill(drone2, SIGSTOP);
          stopped_at = std::stod(line);  // the event's mission time, printed first
        }
        if (line.find("ground: the DEX of Drone1 exited") != std::string::npos ||
            line.find("ground: the DEX of Drone3 exited") != std::string::npos)
          ++others_exited;
        if (drone2 > 0 && !resumed && others_exited == 2) {
          kill(drone2, SIGCONT);
          resumed = true;
        }
      });
  ASSERT_TRUE(resumed) << r.out;
  EXPECT_EQ(r.status, 1) << r.out;
  std::string log = read_text(deploy / "Drone2" / "dex.log");
  EXPECT_NE(log.find("Drone2's DEX stalled for"), std::string::npos) << log;
  EXPECT_NE(log.find("longer than the liveliness lease (1 s)"), std::string::npos) << log;

  double failsafe_at = -1;
  for (const nlohmann::json& e : read_trace(dir_ / "trace.jsonl"))
    if (e["drone"] == "Drone2" && e["event"] == "failsafe") failsafe_at = e["t"];
  ASSERT_GT(failsafe_at, 0) << r.out;
  // Nothing of Drone2's happened while it was frozen, and it started nothing new when it
  // woke: an event dated inside the freeze (from a mission second after the stop, for the
  // signal to land, up to the failsafe) is a replayed one; an action started after it is
  // one the lost mission no longer had the right to run.
  std::vector<std::string> replayed;
  for (const nlohmann::json& e : read_trace(dir_ / "trace.jsonl")) {
    double t = e["t"];
    if (e["drone"] != "Drone2" || t <= stopped_at + 1.0) continue;
    if (t < failsafe_at || e["event"] == "start") replayed.push_back(e.dump());
  }
  EXPECT_TRUE(replayed.empty()) << replayed.front() << "\n" << r.out;
  // Not back-dated: the failsafe is recorded at least a lease (in mission time) after the freeze.
  EXPECT_GE(failsafe_at - stopped_at, lease * speed) << r.out;
  nlohmann::json summary = read_json(dir_ / "summary.json");
  EXPECT_TRUE(summary["drones"]["Drone2"]["landed"]) << summary.dump(2);
  EXPECT_FALSE(summary["drones"]["Drone2"]["armed"]) << summary.dump(2);
}

/// The ground's pid, the parent of the DEX it started.
pid_t parent_of(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
  auto close = text.rfind(')');  // the command name may hold spaces
  if (close == std::string::npos) return -1;
  std::istringstream rest(text.substr(close + 2));
  char state;
  pid_t ppid = -1;
  rest >> state >> ppid;
  return ppid;
}

// The ground stopped (SIGTERM) while both drones hover, one of them run by a DEX started
// elsewhere: each drone's first "failed" status, sent as the failsafe began ("armed, z = 5"
// for a drone that lands seconds later), is not its final state, so the summary waits for
// each drone's state after its failsafe, and the duration is the mission time of the abort.
TEST_F(Faults, InterruptedGroundReportsEachDronesStateAfterItsFailsafeAndTheAbortTime) {
  fs::path deploy = compile(test_mission("long_hover.eamos"));
  eamos_test::EamosProcess wing =
      eamos_test::start_eamos({"dex", (deploy / "Wing").string(), "--speed", "5", "--domain", "161",
                               "--start-timeout", "60"});
  ASSERT_GT(wing.pid, 0);
  int airborne = 0;
  double interrupted_at = -1;
  std::string seen;
  Output r = eamos_test::run_eamos(
      "launch " + deploy.string() + " --drones Lead --speed 5 --domain 161 --summary " +
          (dir_ / "summary.json").string(),
      [&](const std::string& line) {
        seen += line;
        if (interrupted_at < 0 && line.find(".Takeoff(5)  succeeded") != std::string::npos && ++airborne == 2) {
          pid_t ground = parent_of(dex_pid(seen, "Lead"));
          ASSERT_GT(ground, 1) << seen;
          kill(ground, SIGTERM);
          interrupted_at = std::stod(line);
        }
      });
  eamos_test::Exit wing_exit = eamos_test::wait_exit(wing);
  ASSERT_GT(interrupted_at, 0) << r.out;
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_EQ(wing_exit.status, 1) << wing.seen;
  nlohmann::json summary = read_json(dir_ / "summary.json");
  EXPECT_EQ(summary["status"], "failed");
  EXPECT_NE(summary["error"].get<std::string>().find("interrupted (SIGTERM)"), std::string::npos) << summary.dump(2);
  // The abort's mission time: after the second takeoff, well before the landings end.
  EXPECT_GE(summary["duration"].get<double>(), interrupted_at) << summary.dump(2);
  EXPECT_LT(summary["duration"].get<double>(), interrupted_at + 5.0) << summary.dump(2);
  for (const char* d : {"Lead", "Wing"}) {
    EXPECT_TRUE(summary["drones"][d]["landed"]) << d << "\n" << summary.dump(2) << r.out;
    EXPECT_FALSE(summary["drones"][d]["armed"]) << d << "\n" << summary.dump(2);
    EXPECT_LT(summary["drones"][d]["z"].get<double>(), 0.1) << d << "\n" << summary.dump(2);
  }
}

// A drone whose DEX is lost and never comes back has no known final state: its last
// telemetry ("armed, z = 10") is not how it ended.
TEST_F(Faults, DroneLostForGoodIsReportedWithAnUnknownFinalState) {
  fs::path deploy = compile(test_mission("long_hover.eamos"));
  eamos_test::EamosProcess wing = eamos_test::start_eamos(
      {"dex", (deploy / "Wing").string(), "--speed", "5", "--liveliness-timeout", "1", "--domain", "162",
       "--start-timeout", "60"});
  ASSERT_GT(wing.pid, 0);
  int airborne = 0;
  Output r = eamos_test::run_eamos(
      "launch " + deploy.string() + " --drones Lead --speed 5 --liveliness-timeout 1 --final-state-timeout 1 " +
          "--domain 162 --summary " + (dir_ / "summary.json").string(),
      [&](const std::string& line) {
        if (line.find(".Takeoff(5)  succeeded") != std::string::npos && ++airborne == 2) kill(wing.pid, SIGKILL);
      });
  eamos_test::wait_exit(wing);
  ASSERT_EQ(airborne, 2) << r.out;
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("ground: Wing's final state is unknown: no contact since it was lost"), std::string::npos)
      << r.out;
  nlohmann::json summary = read_json(dir_ / "summary.json");
  EXPECT_EQ(summary["drones"]["Wing"]["state"], "unknown") << summary.dump(2);
  EXPECT_FALSE(summary["drones"]["Wing"].contains("landed")) << summary.dump(2);
  EXPECT_FALSE(summary["drones"]["Wing"]["last_seen"]["landed"]) << summary.dump(2);  // where it was
  EXPECT_TRUE(summary["drones"]["Lead"]["landed"]) << summary.dump(2);
}

// The same deployment launched again while it flies: the second ground took the first
// one's READY samples (a drone took off twice, then failsafed). Now it is refused with a
// clear error before anything of it moves, and the first run completes undisturbed.
TEST_F(Faults, SecondLaunchOfARunningDeploymentIsRefusedAndTheFirstCompletes) {
  fs::path deploy = compile(example("listing2.eamos"));
  Output second;
  Output first = eamos_test::run_eamos(
      "launch " + deploy.string() + " --speed 5 --domain 163 --summary " + (dir_ / "summary.json").string(),
      [&](const std::string& line) {
        if (second.status < 0 && line.find("Drone2.Takeoff(10)  succeeded") != std::string::npos)
          second = eamos_test::run_eamos("launch " + deploy.string() + " --speed 5 --domain 163 --barrier-timeout 20");
      });
  ASSERT_GE(second.status, 0) << first.out;
  EXPECT_EQ(second.status, 1) << second.out;
  EXPECT_NE(second.out.find("a second launch of a running deployment is refused"), std::string::npos) << second.out;
  EXPECT_EQ(second.out.find("starting run"), std::string::npos) << second.out;
  EXPECT_EQ(first.status, 0) << first.out;
  EXPECT_EQ(read_json(dir_ / "summary.json")["status"], "completed");
}

// The DEX on a drone (started on its own: any launch may start it) that already flies a
// run answers another START naming it with REFUSED, which that launch prints and fails on.
// The second ground here is a participant of the test's own (--insecure, posing as the
// ground), so that it sends START however fast the real grounds' barrier check would be.
TEST_F(Faults, RunningDexRefusesTheStartOfAnotherLaunch) {
  using namespace eamos::transport;
  Output c = eamos_test::run_eamos("compile -q --insecure " + test_mission("long_hover.eamos") + " -o " +
                                   (dir_ / "deploy").string());
  ASSERT_EQ(c.status, 0) << c.out;
  fs::path deploy = dir_ / "deploy";
  std::string hash = read_json(deploy / "manifest.json")["mission_hash"];
  std::mutex mutex;
  std::condition_variable cv;
  std::uint64_t wing_nonce = 0;
  std::optional<LifecycleSample> refused;
  DdsOptions o;
  o.domain = 164;
  o.mission_hash = hash;
  DdsHandlers h;
  h.limits.drones = 2;
  h.dropped = [](const std::string&) {};
  h.lifecycle = [&](LifecycleSample s) {
    std::lock_guard<std::mutex> lock(mutex);
    if (s.kind == LifecycleKind::ready && s.drone == 1) wing_nonce = s.nonce;
    if (s.kind == LifecycleKind::refused && s.run_id == 12345) refused = s;
    cv.notify_all();
  };
  std::string error;
  std::unique_ptr<DdsNode> second_ground = DdsNode::open(o, std::move(h), error);
  ASSERT_NE(second_ground, nullptr) << error;

  eamos_test::EamosProcess wing = eamos_test::start_eamos(
      {"dex", (deploy / "Wing").string(), "--insecure", "--speed", "5", "--domain", "164", "--start-timeout", "60"});
  ASSERT_GT(wing.pid, 0);
  int airborne = 0;
  bool answered = false;
  std::string seen;
  Output r = eamos_test::run_eamos(
      "launch " + deploy.string() + " --insecure --drones Lead --speed 5 --domain 164",
      [&](const std::string& line) {
        seen += line;
        if (line.find(".Takeoff(5)  succeeded") == std::string::npos || ++airborne != 2) return;
        std::unique_lock<std::mutex> lock(mutex);
        ASSERT_NE(wing_nonce, 0u) << seen;
        LifecycleSample start{hash, kGround, LifecycleKind::start, 12345};
        start.launch_id = 777;
        start.speed = 5;
        start.start_at_ns = 0;
        start.nonces = {1, wing_nonce};
        second_ground->write(start);
        // The refusal is what this waits for; the bound only keeps a broken DEX from hanging the test.
        answered = cv.wait_for(lock, std::chrono::seconds(20), [&] { return refused.has_value(); });
        kill(parent_of(dex_pid(seen, "Lead")), SIGTERM);  // the first run ends, in its failsafe
      });
  eamos_test::wait_exit(wing);
  ASSERT_TRUE(answered) << r.out << wing.seen;
  EXPECT_EQ(refused->drone, 1);
  EXPECT_EQ(refused->launch_id, 777u);
  EXPECT_NE(refused->reason.find("Wing's DEX is already running run"), std::string::npos) << refused->reason;
  EXPECT_NE(wing.seen.find("Wing: refused run 12345 of another launch"), std::string::npos) << wing.seen;
  // The first run did not take the second START: it ended on the SIGTERM, landed.
  EXPECT_NE(r.out.find("interrupted (SIGTERM)"), std::string::npos) << r.out;
  second_ground.reset();
}

}  // namespace
