// Separation kept in flight between processes: each DEX reads the other drones' positions
// from their DDS telemetry and gives way by the same rule as in one process (docs/faults.md,
// "Separation in flight"). Real `eamos run --distributed` processes on loopback at --speed 5,
// domains 170-171; nothing sleeps, the test blocks on the processes.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "trace/trace_schema.h"
#include "support/read_files.h"
#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;

struct Pose {
  double x = 0, y = 0, z = 0;
  bool landed = true;
};

/// The closest two airborne drones came horizontally while nearer than `vertical` m
/// vertically, from the trace's telemetry (each drone's newest sample at each instant).
double closest_horizontal(const fs::path& trace, double vertical = 1.0) {
  std::map<std::string, Pose> last;
  double closest = 1e9;
  std::ifstream in(trace);
  for (std::string line; std::getline(in, line);) {
    nlohmann::json e = nlohmann::json::parse(line);
    if (e["event"] != "telemetry") continue;
    last[e["drone"]] = {e["x"], e["y"], e["z"], e["landed"]};
    for (auto a = last.begin(); a != last.end(); ++a)
      for (auto b = std::next(a); b != last.end(); ++b)
        if (!a->second.landed && !b->second.landed && std::fabs(a->second.z - b->second.z) < vertical)
          closest = std::min(closest, std::hypot(a->second.x - b->second.x, a->second.y - b->second.y));
  }
  return closest;
}

int count(const fs::path& trace, const std::string& event, const std::string& drone) {
  int n = 0;
  std::ifstream in(trace);
  for (std::string line; std::getline(in, line);) {
    nlohmann::json e = nlohmann::json::parse(line);
    n += e["event"] == event && e.value("drone", "") == drone;
  }
  return n;
}

class SeparationDistributed : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eamos-sep-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  eamos_test::Output fly(const std::string& mission, int domain) {
    const std::string m = std::string(EAMOS_SOURCE_DIR) + "/tests/launch/missions/" + mission;
    return eamos_test::run_eamos("run -q " + m + ".eamos --fleet " + m + ".yaml --distributed --speed 5 --domain " +
                                 std::to_string(domain) + " --telemetry-hz 20 --deploy-dir " +
                                 (dir_ / "deploy").string() + " --trace " + trace().string() + " --summary " +
                                 (dir_ / "summary.json").string());
  }
  fs::path trace() const { return dir_ / "trace.jsonl"; }
  /// The mission completes with `yielder` giving way once and resuming, `other` never
  /// giving way, and the two never closer than 2 m.
  void fly_and_expect_one_give_way(const std::string& mission, int domain, const std::string& yielder,
                                   const std::string& other) {
    eamos_test::Output r = fly(mission, domain);
    ASSERT_EQ(r.status, 0) << r.out;
    EXPECT_EQ(count(trace(), "give_way", yielder), 1) << r.out;
    EXPECT_EQ(count(trace(), "resume", yielder), 1);
    EXPECT_EQ(count(trace(), "give_way", other), 0);
    EXPECT_GE(closest_horizontal(trace()), 2.0);
    EXPECT_EQ(schema_errors(), "");
  }

  std::string schema_errors() const {
    std::ifstream in(trace());
    std::vector<std::string> errors = eamos::trace::check_trace(in, {.strict = true});
    return errors.empty() ? "" : errors.front();
  }
  fs::path dir_;
};

TEST_F(SeparationDistributed, CrossingPathsTheLaterDeclaredDroneGivesWayAndBothComplete) {
  fly_and_expect_one_give_way("separation_crossing", 170, "B", "A");
}

TEST_F(SeparationDistributed, HeadOnSwapEndsInTheFailsafeApartAfterTheBound) {
  eamos_test::Output r = fly("separation_head_on", 171);
  ASSERT_EQ(r.status, 1) << r.out;
  nlohmann::json summary = eamos_test::read_json(dir_ / "summary.json");
  EXPECT_EQ(summary["status"], "failed");
  EXPECT_NE(summary["error"].get<std::string>().find("for 30.0 s and its course is still not clear"),
            std::string::npos)
      << summary["error"];
  EXPECT_GE(count(trace(), "give_way", "B"), 1);
  EXPECT_GE(closest_horizontal(trace()), 2.0);
  EXPECT_TRUE(summary["drones"]["A"]["landed"]);
  EXPECT_TRUE(summary["drones"]["B"]["landed"]);
  EXPECT_EQ(schema_errors(), "");
}

TEST_F(SeparationDistributed, ADroneHoveringOnAnothersPathIsWaitedForAndBothComplete) {
  fly_and_expect_one_give_way("separation_hover_on_path", 172, "A", "B");
}

TEST_F(SeparationDistributed, ThreeConvergingDronesPassOneAtATime) {
  eamos_test::Output r = fly("separation_three", 173);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(count(trace(), "give_way", "A"), 0) << r.out;
  EXPECT_GE(count(trace(), "give_way", "B") + count(trace(), "give_way", "C"), 2) << r.out;
  EXPECT_EQ(count(trace(), "give_way", "B") + count(trace(), "give_way", "C"),
            count(trace(), "resume", "B") + count(trace(), "resume", "C"));
  EXPECT_GE(closest_horizontal(trace()), 2.0);
  EXPECT_EQ(schema_errors(), "");
}

}  // namespace
