#pragma once
// Compiling missions for the deploy tests: Listing 2 with a fleet file that sets every
// kind of per-drone setting, and generated stress missions.
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "graph/pipeline.h"
#include "stress/generator.h"

namespace eamos::test {

/// Every per-drone setting a mission file carries, with values that are not integers.
inline const char* kListing2Fleet =
    "drones:\n"
    "  Drone1:\n"
    "    home: [0.25, -3, 1.5]\n"
    "    battery: 87.5\n"
    "    sensors:\n"
    "      Sensor1: 120\n"
    "      Sensor2: {value: 10.1, gradient: [0.5, 0, -0.125]}\n"
    "    limits: {max_speed: 5.5}\n"
    "  Drone2:\n"
    "    failsafe: return_home\n"
    "    adapter: mavlink\n"
    "    connection: udp://:14540\n"
    "    sysid: 7\n"
    "    timeouts: {Takeoff: 40, FlyTo: 120.5}\n";

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline std::string listing2_text() {
  return read_text(std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos");
}

/// Compiles `text` (and the fleet file text, when not empty); fails the test on errors.
inline std::unique_ptr<graph::Compilation> compile_mission(const std::string& text,
                                                           const std::string& fleet_text = "") {
  auto c = std::make_unique<graph::Compilation>();
  Diagnostics diags;
  fleet::Fleet fleet;
  if (!fleet_text.empty() &&
      !fleet::parse_fleet(std::make_shared<SourceFile>("fleet.yaml", fleet_text), fleet, diags)) {
    ADD_FAILURE() << "fleet file did not load:\n" << diags.format();
    return nullptr;
  }
  if (!graph::compile(std::make_shared<SourceFile>("mission.eamos", text), fleet, diags, *c)) {
    ADD_FAILURE() << "mission did not compile:\n" << diags.format();
    return nullptr;
  }
  return c;
}

inline std::string stress_text(long long nodes, int drones) {
  stress::StressOptions o;
  o.target_nodes = nodes;
  o.drones = drones;
  return stress::generate_mission(o);
}

}  // namespace eamos::test
