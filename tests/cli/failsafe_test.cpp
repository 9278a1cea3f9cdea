// What `eamos run` does once a failed action abandons the mission and each drone flies its
// fleet failsafe: through the real process, from the trace and the summary it writes.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "support/read_files.h"
#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;
const std::string kMissions = std::string(EAMOS_SOURCE_DIR) + "/tests/launch/missions/";

class RunFailsafe : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eamos-failsafe-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  fs::path dir_;
};

// Late's Takeoff is refused while Lead climbs; Lead's failsafe is `hover`: it holds where it
// is at once, so the run has nothing left to wait for and ends at the failure, instead of
// flying the hovering drone for the 600 mission s bound (its battery drained to 40 %).
TEST_F(RunFailsafe, RunEndsAsSoonAsAHoveringFailsafeHolds) {
  eamos_test::Output r = eamos_test::run_eamos(
      "run -q " + kMissions + "refused_takeoff.eamos --fleet " + kMissions + "hover_failsafe.yaml --trace " +
      (dir_ / "trace.jsonl").string() + " --summary " + (dir_ / "summary.json").string());
  EXPECT_EQ(r.status, 1) << r.out;
  nlohmann::json summary = eamos_test::read_json(dir_ / "summary.json");
  EXPECT_EQ(summary["failure"]["drone"], "Late") << summary.dump(2);
  const nlohmann::json& lead = summary["drones"]["Lead"];
  EXPECT_FALSE(lead["landed"]) << lead.dump();  // hovering, as told
  EXPECT_TRUE(lead["armed"]) << lead.dump();
  EXPECT_GT(lead["battery"].get<double>(), 95.0) << lead.dump();
  // The trace's telemetry (5 Hz) ends with the run: within a sample of the failure.
  double failed_at = summary["duration"].get<double>(), last = 0.0;
  bool failsafe = false;
  for (const nlohmann::json& e : eamos_test::read_trace(dir_ / "trace.jsonl")) {
    last = std::max(last, e["t"].get<double>());
    if (e.value("event", "") == "failsafe" && e.value("drone", "") == "Lead") failsafe = e["name"] == "hover";
  }
  EXPECT_TRUE(failsafe);
  EXPECT_LE(last, failed_at + 0.2);
}

}  // namespace
