// The terminal's status line says on whom an idle drone waits: Listing 2 flown in the
// simulator, its real trace fed event by event into the status display, every line read.
#include <gtest/gtest.h>

#include <set>
#include <sstream>

#include "cli/commands.h"
#include "cli/progress.h"
#include "dex/runner.h"
#include "dex/trace_writers.h"
#include "graph/pipeline.h"
#include "sim/sim_adapter.h"

namespace {

// Every status line drawn after each event of a Listing 2 run with `fleet`.
std::vector<std::string> status_lines(const std::string& fleet) {
  eamos::Diagnostics diags;
  eamos::graph::Compilation c;
  std::string root = EAMOS_SOURCE_DIR;
  EXPECT_TRUE(eamos::graph::compile_file(root + "/examples/listing2.eamos", root + "/examples/" + fleet, diags, c))
      << diags.format();
  std::vector<eamos::dex::Mission> missions;
  EXPECT_TRUE(eamos::cli::load_compiled_missions(c, missions));
  eamos::mid::AdapterRegistry adapters;
  eamos::sim::register_adapter(adapters);
  eamos::dex::MemoryTrace trace;
  eamos::dex::RunResult result = eamos::dex::run_in_process(missions, adapters, &trace, {});
  EXPECT_TRUE(result.completed) << result.error;
  std::ostringstream screen;
  eamos::cli::ProgressDisplay display(screen, missions);
  std::vector<std::string> lines;
  for (const eamos::dex::TraceEvent& e : trace.events) {
    display.record(e);
    for (const std::string& l : display.lines()) lines.push_back(l);
  }
  return lines;
}

::testing::AssertionResult any_line(const std::vector<std::string>& lines, const std::string& drone,
                                    const std::string& text) {
  std::set<std::string> seen;  // what the drone's line said instead (its time column cut)
  for (const std::string& l : lines) {
    if (l.rfind(drone, 0) != 0) continue;
    if (l.find(text) != std::string::npos) return ::testing::AssertionSuccess();
    seen.insert(l.substr(l.find(" s  ") + 4));
  }
  auto failure = ::testing::AssertionFailure() << drone << " never says '" << text << "'; it says:";
  for (const std::string& s : seen) failure << "\n  " << s;
  return failure;
}

TEST(Waiting, AnIdleDroneNamesTheConditionOrTheDronesItWaitsFor) {
  std::vector<std::string> lines = status_lines("listing2-right.yaml");
  // Drone3's WaitUntil holds it until Drone1 has flown 4.5 m.
  EXPECT_TRUE(any_line(lines, "Drone3", "waiting until Drone1.X() >= 4.5 || Drone1.X() <= -4.5"));
  // (The condition is Drone1's to evaluate: Drone3 waits on it, and the line names the condition.)
  // At the PAR that disarms every drone, the drones that landed first wait for Drone2, which
  // still takes pictures and lands last.
  EXPECT_TRUE(any_line(lines, "Drone1", "waiting for Drone2"));
  // Nobody is said to wait on itself, and a named drone is one of the fleet.
  for (const std::string& l : lines) {
    std::string drone = l.substr(0, 6);
    EXPECT_EQ(l.find("waiting for " + drone), std::string::npos) << l;
  }
}

}  // namespace
