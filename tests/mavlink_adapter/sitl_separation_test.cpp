// Separation kept in flight on real autopilot firmware: two ArduCopter SITL vehicles whose
// FlyTo legs cross at one point at the same moment. The later declared gives way (its
// position setpoint moves to where it stands), flies on once the first has passed (its goal
// sent again), and no two vehicles come closer than min_separation (docs/faults.md,
// "Separation in flight"). Skipped without EAMOS_ARDUPILOT_SITL.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "support/run_eamos.h"
#include "support/sitl.h"

namespace {

namespace fs = std::filesystem;
using eamos_test::Autopilot;
using eamos_test::SitlFleet;

constexpr double kSpeed = 5;

struct Seen {
  int give_ways = 0, resumes = 0;
  std::string gave_way;     ///< the drone of the first give_way
  double closest_m = 1e9;   ///< horizontally, of two airborne drones within 1 m vertically
};

Seen read_trace(const fs::path& trace) {
  Seen s;
  std::map<std::string, nlohmann::json> last;
  std::ifstream in(trace);
  for (std::string line; std::getline(in, line);) {
    auto e = nlohmann::json::parse(line, nullptr, false);
    if (e.is_discarded()) continue;
    const std::string event = e.value("event", "");
    if (event == "give_way" && s.give_ways++ == 0) s.gave_way = e.value("drone", "");
    if (event == "resume") ++s.resumes;
    if (event != "telemetry") continue;
    last[e["drone"]] = e;
    for (auto a = last.begin(); a != last.end(); ++a)
      for (auto b = std::next(a); b != last.end(); ++b) {
        const nlohmann::json &p = a->second, &q = b->second;
        if (p["landed"] || q["landed"] || std::fabs(p["z"].get<double>() - q["z"].get<double>()) >= 1.0) continue;
        s.closest_m = std::min(s.closest_m, std::hypot(p["x"].get<double>() - q["x"].get<double>(),
                                                       p["y"].get<double>() - q["y"].get<double>()));
      }
  }
  return s;
}

// Both vehicles set off from a hover towards the crossing: B is predicted along the line to its
// goal, so it gives way before it speeds up, not once its samples show the speed.
TEST(SitlSeparation, TwoArduCoptersCrossingOneGivesWayAndBothComplete) {
  if (SitlFleet::binary(Autopilot::ardupilot).empty()) GTEST_SKIP() << SitlFleet::skip_message(Autopilot::ardupilot);
  const std::vector<eamos_test::SitlHome> homes = {{-30, 0}, {0, -30}};
  fs::path dir = fs::temp_directory_path() / ("eamos-sitl-separation-" + std::to_string(getpid()));
  fs::create_directories(dir);
  SitlFleet sitl(eamos_test::SitlOptions{Autopilot::ardupilot, homes, kSpeed});
  std::string error;
  ASSERT_TRUE(sitl.start(error) && sitl.wait_ready(120, error)) << error;
  std::string fleet = "drones:\n";
  const char* names[] = {"A", "B"};
  for (int i = 0; i < 2; ++i)
    fleet += std::string("  ") + names[i] + ": {adapter: mavlink, connection: \"" + sitl.connection(i) +
             "\", sysid: " + std::to_string(sitl.sysid(i)) + ", home: [" + std::to_string(homes[i].x) + ", " +
             std::to_string(homes[i].y) + ", 0]}\n";
  std::ofstream(dir / "fleet.yaml") << fleet;
  const std::string mission = std::string(EAMOS_SOURCE_DIR) + "/tests/launch/missions/separation_crossing.eamos";
  eamos_test::Output r = eamos_test::run_eamos("run " + mission + " --fleet " + (dir / "fleet.yaml").string() +
                                               " --speed 5 --time-limit 300 --telemetry-hz 10 --trace " +
                                               (dir / "trace.jsonl").string());
  EXPECT_EQ(r.status, 0) << r.out;
  Seen s = read_trace(dir / "trace.jsonl");
  // Each run's closest approach, pass or fail: how far from the minimum the runs stay.
  std::cout << "[sitl] closest " << s.closest_m << " m, " << s.give_ways << " give-way(s)\n";
  EXPECT_EQ(s.gave_way, "B") << r.out;
  EXPECT_GE(s.resumes, 1) << r.out;
  EXPECT_EQ(s.give_ways, s.resumes);
  EXPECT_GE(s.closest_m, 2.0);
  if (!HasFailure()) fs::remove_all(dir);
}

}  // namespace
