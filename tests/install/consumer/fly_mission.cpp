// Compiles a mission text and flies it in the simulator with the same calls `eamos run`
// makes (src/cli/run.cpp): graph::compile, each drone's mission file written and read back
// through the validating reader, dex::run_in_process with the sim adapter. Built against an
// installed eamos by tests/install/install_test.cpp. Prints every diagnostic and a last
// line "completed in T s" or "failed: REASON"; exit 0 only when the mission completed.
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "deploy/mission_file.h"
#include "dex/runner.h"
#include "dex/trace_writers.h"
#include "graph/pipeline.h"
#include "sim/sim_adapter.h"
#include "version.h"

namespace {

const char* kMission = R"(var Drone1 Quad
var Drone2 Quad

func INIT() { SEQ_mission() }

func SEQ_mission() {
  PAR_arm()
  PAR_takeoff()
  If(Drone1.Sensor1() >= 100, SEQ_right, SEQ_left)
  PAR_land()
}
func PAR_arm() { Drone1.Arm(); Drone2.Arm() }
func PAR_takeoff() { Drone1.Takeoff(3); Drone2.Takeoff(5) }
func SEQ_right() { Drone1.FlyByX(5) }
func SEQ_left() { Drone1.FlyByX(-5) }
func PAR_land() { Drone1.Land(); Drone2.Land() }
)";

}  // namespace

int main() {
  using namespace eamos;
  std::cout << "built against eamos " << EAMOS_VERSION << "\n";
  Diagnostics diags;
  graph::Compilation c;
  bool ok = graph::compile(std::make_shared<SourceFile>("consumer.eamos", kMission), fleet::Fleet{}, diags, c);
  std::cerr << diags.format();
  if (!ok) return 1;

  std::string hash = deploy::mission_hash(c);
  std::vector<dex::Mission> missions(c.drone_count());
  for (int d = 0; d < c.drone_count(); ++d) {
    std::vector<std::string> errors;
    if (!deploy::read_mission(deploy::mission_text(c, d, hash), c.drone_name(d) + "/mission.json", missions[d],
                              errors)) {
      for (const std::string& e : errors) std::cerr << e << "\n";
      return 1;
    }
  }
  mid::AdapterRegistry adapters;
  sim::register_adapter(adapters);
  dex::MemoryTrace trace;
  dex::RunResult result = dex::run_in_process(missions, adapters, &trace);
  std::cout << trace.events.size() << " trace events\n";
  if (!result.completed) {
    std::cout << "failed: " << result.error << "\n";
    return 1;
  }
  std::cout << "completed in " << result.duration << " s\n";
  return 0;
}
