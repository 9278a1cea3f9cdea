// Every failure the simulator produces reaches the trace, the summary and `eamos verify
// --json` with its uniform kind (FailureReason) beside the outcome string, which stays
// "failed"; the vehicle's own words ride along as its detail.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;
const std::string kData = std::string(EAMOS_SOURCE_DIR) + "/tests/cli/data/failure/";

struct Failed {
  int status = -1;
  std::string out;
  nlohmann::json end;      ///< the trace's `end` event with outcome "failed"
  nlohmann::json summary;  ///< the summary's "failure"
};

Failed run_failing(const std::string& mission, const std::string& fleet, const std::string& options = "") {
  fs::path dir = fs::temp_directory_path() /
                 ("eamos-failure-" + std::to_string(::getpid()) + "-" +
                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::create_directories(dir);
  eamos_test::Output r = eamos_test::run_eamos("run " + kData + mission + (fleet.empty() ? "" : " --fleet " + kData + fleet) +
                                               " --trace " + (dir / "trace.jsonl").string() + " --summary " +
                                               (dir / "summary.json").string() + (options.empty() ? "" : " " + options));
  Failed f{r.status, r.out, {}, {}};
  std::ifstream trace(dir / "trace.jsonl");
  for (std::string line; std::getline(trace, line);) {
    auto e = nlohmann::json::parse(line);
    if (e.value("event", "") == "end" && e.value("outcome", "") == "failed") f.end = e;
  }
  std::ifstream summary(dir / "summary.json");
  if (summary) f.summary = nlohmann::json::parse(summary)["failure"];
  fs::remove_all(dir);
  return f;
}

TEST(SimFailureReasons, ARefusalIsRefusedInTheTraceAndTheSummary) {
  Failed f = run_failing("takeoff-disarmed.eamos", "");
  EXPECT_EQ(f.status, 1) << f.out;
  ASSERT_TRUE(f.end.is_object()) << f.out;
  EXPECT_EQ(f.end["name"], "Takeoff");
  EXPECT_EQ(f.end["failure"], "refused");
  EXPECT_EQ(f.end["reason"], "disarmed: arm before Takeoff");
  EXPECT_EQ(f.summary["kind"], "refused");
  EXPECT_NE(f.out.find("failed [refused]"), std::string::npos) << f.out;  // the live log
}

// A DEX process's failed action reaches the ground's live log and trace with its kind, the
// same line an in-process run prints (DDS domain 203, used by no other test).
TEST(SimFailureReasons, ARefusalInADistributedRunIsRefusedInTheLogAndTheTrace) {
  Failed f = run_failing("takeoff-disarmed.eamos", "", "--distributed --insecure --speed 5 --domain 203");
  EXPECT_EQ(f.status, 1) << f.out;
  ASSERT_TRUE(f.end.is_object()) << f.out;
  EXPECT_EQ(f.end["failure"], "refused");
  EXPECT_NE(f.out.find("Takeoff(3)  failed [refused]  (disarmed: arm before Takeoff)"), std::string::npos) << f.out;
}

TEST(SimFailureReasons, ADeadlineIsTimedOutWithTheDeadlineAsDetail) {
  Failed f = run_failing("far-flight.eamos", "short-timeout.yaml");
  EXPECT_EQ(f.status, 1) << f.out;
  ASSERT_TRUE(f.end.is_object()) << f.out;
  EXPECT_EQ(f.end["name"], "FlyTo");
  EXPECT_EQ(f.end["failure"], "timed_out");
  EXPECT_EQ(f.end["reason"], "timed out after 2.0 s");
  EXPECT_EQ(f.end["detail"], "deadline 2.0 s after start");
  EXPECT_EQ(f.summary["kind"], "timed_out");
  EXPECT_EQ(f.summary["detail"], "deadline 2.0 s after start");
}

TEST(SimFailureReasons, AnEmptyBatteryIsAVehicleFaultWithTheChargeAsDetail) {
  Failed f = run_failing("far-flight.eamos", "low-battery.yaml");
  EXPECT_EQ(f.status, 1) << f.out;
  ASSERT_TRUE(f.end.is_object()) << f.out;
  EXPECT_EQ(f.end["name"], "FlyTo");
  EXPECT_EQ(f.end["failure"], "vehicle_fault");
  EXPECT_EQ(f.end["reason"], "battery empty");
  EXPECT_EQ(f.end["detail"], "battery at 0.0 %");
  EXPECT_EQ(f.summary["kind"], "vehicle_fault");
}

TEST(SimFailureReasons, VerifyJsonNamesTheKindOfAFailedAction) {
  eamos_test::Output r = eamos_test::run_eamos("verify " + kData + "takeoff-disarmed.eamos --json");
  auto j = nlohmann::json::parse(r.out.substr(r.out.find('{')));
  bool seen = false;
  for (const auto& v : j["violations"])
    if (v["kind"] == "action_failed") {
      seen = true;
      EXPECT_EQ(v["failure"], "refused") << v.dump();
    }
  EXPECT_TRUE(seen) << r.out;
}

}  // namespace
