#pragma once
// The Mission Compiler's stages in order (paper, Fig. 4): parse → check → AMT → MEG →
// MDGs. One Compilation owns everything a stage produced, so later stages and tools
// (graph export, synthesis, benchmarks) can point into earlier ones without copying.
#include <memory>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "fleet/fleet.h"
#include "graph/amt.h"
#include "graph/mdg.h"
#include "graph/meg.h"
#include "lang/ast.h"
#include "lang/checker.h"

namespace eamos::graph {

struct Compilation {
  std::shared_ptr<SourceFile> source;
  fleet::Fleet fleet;
  lang::Mission mission;
  lang::CheckedMission checked;
  std::vector<fleet::DroneSettings> settings;  ///< per declared drone
  Amt amt;
  Meg meg;
  std::vector<Mdg> mdgs;

  int drone_count() const { return static_cast<int>(mission.drones.size()); }
  const std::string& drone_name(int d) const { return mission.drones[d].name; }
  int find_drone(const std::string& name) const { return mission.find_drone(name); }
};

/// Which graphs a Compilation keeps. A deployment needs only the MEG and the MDGs; the
/// AMT serves tools (graph export, stats), and a compile that does not build it holds
/// about a tenth less memory at its peak.
enum class Keep {
  all_graphs,
  /// No AMT is built. The statements other than control structures are freed once the MEG
  /// is built, the rest once the MEG is checked.
  deployment_graphs,
};

/// Runs every stage on `source`; stops after the first stage that reported errors.
/// Returns true when the graphs are complete (warnings allowed).
bool compile(std::shared_ptr<SourceFile> source, const fleet::Fleet& fleet, Diagnostics& diags,
             Compilation& out, const lang::CheckLimits& limits = {}, Keep keep = Keep::all_graphs);

/// Reads the mission (and the fleet file when `fleet_path` is not empty) and compiles.
bool compile_file(const std::string& path, const std::string& fleet_path, Diagnostics& diags,
                  Compilation& out, Keep keep = Keep::all_graphs);

}  // namespace eamos::graph
