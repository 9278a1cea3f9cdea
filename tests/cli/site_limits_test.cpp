// The fleet's `safety:` rules kept in flight by `eamos run` (one process) and by the DEXes of
// `eamos run --distributed`: a target outside the geofence or above its max_altitude is
// refused before the drone moves, a drone pushed out of the fence fails over at once, and
// the site's speed limits cap what the drone flies. Through the real process, from the
// trace and the summary it writes.
#include <gtest/gtest.h>

#include <unistd.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/read_files.h"
#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;
const std::string kData = std::string(EAMOS_SOURCE_DIR) + "/tests/cli/data/site/";

class SiteLimits : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eamos-site-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  /// `eamos run MISSION --fleet FLEET` with a trace and a summary; `extra` adds options.
  eamos_test::Output run(const std::string& mission, const std::string& fleet, const std::string& extra = "") {
    return eamos_test::run_eamos("run -q " + kData + mission + " --fleet " + kData + fleet + " " + extra +
                                 " --trace " + (dir_ / "trace.jsonl").string() + " --summary " +
                                 (dir_ / "summary.json").string());
  }
  nlohmann::json summary() { return eamos_test::read_json(dir_ / "summary.json"); }
  /// The largest |x| Drone1's telemetry ever showed, and whether its failsafe is traced.
  double farthest_x(bool& failsafe) {
    double far = 0.0;
    failsafe = false;
    for (const nlohmann::json& e : eamos_test::read_trace(dir_ / "trace.jsonl")) {
      if (e.value("event", "") == "failsafe" && e.value("drone", "") == "Drone1") failsafe = true;
      if (e.value("event", "") == "telemetry" && e.value("drone", "") == "Drone1")
        far = std::max(far, std::abs(e["x"].get<double>()));
    }
    return far;
  }
  void expect_down_and_disarmed() {
    nlohmann::json d = summary()["drones"]["Drone1"];
    EXPECT_TRUE(d["landed"]) << d.dump();
    EXPECT_FALSE(d["armed"]) << d.dump();
  }
  fs::path dir_;
};

TEST_F(SiteLimits, AFlyToOutsideTheFenceIsRefusedBeforeTheDroneMoves) {
  eamos_test::Output r = run("outside.eamos", "fence.yaml");
  EXPECT_EQ(r.status, 1) << r.out;
  nlohmann::json s = summary();
  EXPECT_EQ(s["failure"]["action"], "FlyTo") << s.dump(2);
  EXPECT_EQ(s["failure"]["kind"], "refused");
  std::string error = s["error"];
  EXPECT_NE(error.find("Drone1 FlyTo: target (30.0, 0.0, 5.0) is outside its polygon"), std::string::npos) << error;
  bool failsafe = false;
  EXPECT_LT(farthest_x(failsafe), 0.01);  // it never left its home's vertical
  EXPECT_TRUE(failsafe);
  expect_down_and_disarmed();
}

TEST_F(SiteLimits, ATargetAboveTheFencesMaxAltitudeIsRefused) {
  eamos_test::Output r = run("too_high.eamos", "fence.yaml");
  EXPECT_EQ(r.status, 1) << r.out;
  nlohmann::json s = summary();
  EXPECT_EQ(s["failure"]["action"], "FlyByZ") << s.dump(2);
  EXPECT_NE(s["error"].get<std::string>().find("target (0.0, 0.0, 17.0) is above its max_altitude 15.0 m"),
            std::string::npos)
      << s["error"];
  expect_down_and_disarmed();
}

// The gust pushes Drone1 east at 4 m/s while it hovers: the first step that finds it past
// x = 10 (0.2 m further per step at 20 Hz) puts it in its failsafe, and Hover fails.
TEST_F(SiteLimits, ADronePushedOutOfTheFenceIsPutInItsFailsafeAtOnce) {
  eamos_test::Output r = run("hover.eamos", "gust.yaml");
  EXPECT_EQ(r.status, 1) << r.out;
  nlohmann::json s = summary();
  EXPECT_EQ(s["failure"]["action"], "Hover") << s.dump(2);
  EXPECT_EQ(s["failure"]["kind"], "vehicle_fault");
  std::string error = s["error"];
  EXPECT_NE(error.find("Drone1 left its geofence at (10."), std::string::npos) << error;
  EXPECT_NE(error.find("its failsafe (land) was commanded"), std::string::npos) << error;
  double x = summary()["drones"]["Drone1"]["x"];
  EXPECT_LE(x, 10.25 + 4.0 * 0.1);  // landing straight down where it was; the gust may push it on while it lands
  bool failsafe = false;
  farthest_x(failsafe);
  EXPECT_TRUE(failsafe);
  expect_down_and_disarmed();
}

// Between actions (a PauseFor) no action can carry the fault: the drone reports it itself.
TEST_F(SiteLimits, ADronePushedOutWhileNoActionRunsFailsTheMission) {
  eamos_test::Output r = run("pause.eamos", "gust.yaml");
  EXPECT_EQ(r.status, 1) << r.out;
  std::string error = summary()["error"];
  EXPECT_EQ(error.rfind("Drone1 left its geofence at (10.", 0), 0u) << error;
  bool failsafe = false;
  farthest_x(failsafe);
  EXPECT_TRUE(failsafe);
  expect_down_and_disarmed();
}

// The vehicle could fly 10 m/s; the site allows 2 m/s horizontally and 1 m/s up. Speeds are
// measured over half a second of 20 Hz telemetry: the Mover's last step ends exactly on the
// target, a few millimetres longer than the others.
TEST_F(SiteLimits, TheSitesSpeedLimitsCapTheFlight) {
  eamos_test::Output r = run("inside.eamos", "fence.yaml", "--telemetry-hz 20");
  ASSERT_EQ(r.status, 0) << r.out;
  std::vector<std::array<double, 4>> track;  // t, x, y, z
  for (const nlohmann::json& e : eamos_test::read_trace(dir_ / "trace.jsonl"))
    if (e.value("event", "") == "telemetry" && e.value("drone", "") == "Drone1")
      track.push_back({e["t"].get<double>(), e["x"].get<double>(), e["y"].get<double>(), e["z"].get<double>()});
  double fastest = 0.0, fastest_up = 0.0;
  for (std::size_t i = 10; i < track.size(); ++i) {
    const auto &a = track[i - 10], &b = track[i];
    fastest = std::max(fastest, std::hypot(b[1] - a[1], b[2] - a[2]) / (b[0] - a[0]));
    fastest_up = std::max(fastest_up, (b[3] - a[3]) / (b[0] - a[0]));
  }
  EXPECT_GT(fastest, 1.9);  // it did fly, at the cap
  EXPECT_LE(fastest, 2.0 + 0.03);
  EXPECT_GT(fastest_up, 0.9);
  EXPECT_LE(fastest_up, 1.0 + 0.03);
}

// The same refusal with one DEX per drone over DDS: the rules travel in the mission file.
TEST_F(SiteLimits, DistributedAFlyToOutsideTheFenceIsRefusedBeforeTheDroneMoves) {
  eamos_test::Output r = run("outside.eamos", "fence.yaml",
                             "--distributed --speed 5 --domain 212 --deploy-dir " + (dir_ / "deploy").string());
  EXPECT_EQ(r.status, 1) << r.out;
  nlohmann::json s = summary();
  EXPECT_EQ(s["failure"]["action"], "FlyTo") << s.dump(2);
  EXPECT_EQ(s["failure"]["kind"], "refused");
  EXPECT_NE(s["error"].get<std::string>().find("is outside its polygon"), std::string::npos) << s["error"];
  bool failsafe = false;
  EXPECT_LT(farthest_x(failsafe), 0.01);
  EXPECT_TRUE(failsafe);
  expect_down_and_disarmed();
}

// One DEX per drone: Drone1 is pushed out while it pauses (no action to carry the fault);
// its DEX fails over and its ABORT puts Drone2, on another process, in its failsafe too.
TEST_F(SiteLimits, DistributedADronePushedOutPutsEveryDroneInItsFailsafe) {
  eamos_test::Output r = run("two.eamos", "gust_two.yaml",
                             "--distributed --speed 5 --domain 213 --deploy-dir " + (dir_ / "deploy").string());
  EXPECT_EQ(r.status, 1) << r.out;
  nlohmann::json s = summary();
  EXPECT_EQ(s["error"].get<std::string>().rfind("Drone1 left its geofence at (10.", 0), 0u) << s.dump(2);
  std::set<std::string> failsafes;
  for (const nlohmann::json& e : eamos_test::read_trace(dir_ / "trace.jsonl"))
    if (e.value("event", "") == "failsafe") failsafes.insert(e.value("drone", ""));
  EXPECT_EQ(failsafes, (std::set<std::string>{"Drone1", "Drone2"})) << r.out;
  for (const char* d : {"Drone1", "Drone2"}) {
    EXPECT_TRUE(s["drones"][d]["landed"]) << d;
    EXPECT_FALSE(s["drones"][d]["armed"]) << d;
  }
}

}  // namespace
