// Missions flown by `eamos run` against real autopilot firmware: ArduCopter and PX4 (SIH)
// SITL, three instances each, started and stopped by the test (tests/support/sitl.h). Skip,
// saying how to get SITL, when EAMOS_ARDUPILOT_SITL / EAMOS_PX4_SITL is not set.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "support/run_eamos.h"
#include "support/sitl.h"

namespace {

namespace fs = std::filesystem;
using eamos_test::Autopilot;
using eamos_test::SitlFleet;

// The speed-up both sides run at: SITL's simulation and eamos' --speed (its wall-clock
// budgets scale with it). Chosen so that three instances stay real-time on two cores.
constexpr double kSpeed = 5;

struct Flight {
  eamos_test::Output run;
  std::map<std::string, std::vector<std::string>> actions;  ///< drone -> "Action outcome"
};

// The autopilots' own vertical speeds, which action timeouts must be derived from: the
// adapter does not read them from the vehicle yet, so the fleet file states them, as
// docs/adapters.md tells a user to. ArduCopter: WPNAV_SPEED_UP 2.5, LAND_SPEED 0.5 m/s.
// PX4: MPC_TKO_SPEED 1.5 m/s after a slow spool-up, MPC_LAND_SPEED 0.7 m/s.
std::string limits(Autopilot a) {
  return a == Autopilot::ardupilot ? "{max_climb: 2.5, max_descent: 0.5}" : "{max_climb: 1, max_descent: 0.7}";
}

std::string fleet_file(const SitlFleet& sitl, Autopilot a, const std::vector<eamos_test::SitlHome>& homes) {
  std::string y = "types:\n  Quad: {adapter: mavlink, limits: " + limits(a) + "}\ndrones:\n";
  for (int i = 0; i < sitl.size(); ++i)
    y += "  Drone" + std::to_string(i + 1) + ": {connection: \"" + sitl.connection(i) +
         "\", sysid: " + std::to_string(sitl.sysid(i)) + ", home: [" + std::to_string(homes[i].x) +
         ", " + std::to_string(homes[i].y) + ", 0]}\n";
  return y;
}

Flight fly(const std::string& mission, const std::string& fleet_yaml, const fs::path& dir) {
  std::ofstream(dir / "fleet.yaml") << fleet_yaml;
  Flight f;
  f.run = eamos_test::run_eamos("run " + mission + " --fleet " + (dir / "fleet.yaml").string() +
                                " --speed " + std::to_string(kSpeed) + " --trace " +
                                (dir / "trace.jsonl").string());
  std::ifstream in(dir / "trace.jsonl");
  for (std::string line; std::getline(in, line);) {
    auto e = nlohmann::json::parse(line, nullptr, false);
    if (e.is_discarded() || e.value("event", "") != "end") continue;
    f.actions[e.value("drone", "")].push_back(e.value("text", "") + " " + e.value("outcome", ""));
  }
  return f;
}

class Sitl : public ::testing::TestWithParam<Autopilot> {
 protected:
  void SetUp() override {
    if (SitlFleet::binary(GetParam()).empty()) GTEST_SKIP() << SitlFleet::skip_message(GetParam());
    dir_ = fs::temp_directory_path() / ("eamos-sitl-test-" + std::to_string(getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path dir_;
};

TEST_P(Sitl, ThreeDronesArmTakeOffFlyAndLandOnTheRealAutopilot) {
  std::vector<eamos_test::SitlHome> homes = {{0, 0}, {0, 5}, {0, 10}};
  SitlFleet sitl({GetParam(), homes, kSpeed});
  std::string error;
  ASSERT_TRUE(sitl.start(error)) << error;
  ASSERT_TRUE(sitl.wait_ready(120, error)) << error;
  Flight f = fly(std::string(EAMOS_SOURCE_DIR) + "/tests/mavlink_adapter/missions/three_hops.eamos",
                 fleet_file(sitl, GetParam(), homes), dir_);
  ASSERT_EQ(f.run.status, 0) << f.run.out;
  for (int d = 1; d <= 3; ++d) {
    std::string n = "Drone" + std::to_string(d);
    std::vector<std::string> want = {n + ".Arm() succeeded", n + ".Takeoff(" + std::to_string(d + 3) + ") succeeded",
                                     n + ".FlyByX(3) succeeded", n + ".Land() succeeded",
                                     n + ".Disarm() succeeded"};
    EXPECT_EQ(f.actions[n], want) << f.run.out;
  }
}

INSTANTIATE_TEST_SUITE_P(Autopilots, Sitl, ::testing::Values(Autopilot::ardupilot, Autopilot::px4),
                         [](const auto& info) {
                           return info.param == Autopilot::ardupilot ? std::string("ArduCopter")
                                                                     : std::string("PX4");
                         });

}  // namespace
