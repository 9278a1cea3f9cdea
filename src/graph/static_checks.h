#pragma once
// Static analysis of a mission's logic before anything flies: waits that
// can never end, loops that never end, branches that can never run, and cross-drone
// deadlock, found on the MEG. Every finding is a fact that holds on every flight where the
// statement is reached; what eamos cannot prove is not reported (docs/verify.md, "Static
// checks", lists the rules and what each assumes).
#include <vector>

#include "diag/diagnostics.h"
#include "fleet/fleet.h"
#include "graph/meg.h"
#include "lang/ast.h"

namespace eamos::graph {

struct StaticCheckInput {
  const Meg& meg;
  const lang::Mission& mission;
  const fleet::Fleet& fleet;
  const std::vector<fleet::DroneType>& types;        ///< per declared drone
  const std::vector<fleet::DroneSettings>& settings;  ///< per declared drone
};

/// Bounds the work on huge missions: each analysed condition costs a pass over the MEG.
/// Past the budget the remaining conditions are not analysed (nothing is reported on them).
struct StaticCheckLimits {
  long long max_node_visits = 30'000'000;
};

/// Reports an error where the mission can never complete once it gets there (a wait or a
/// loop that never ends, a deadlock) and a warning where it completes but part of what is
/// written can never run (a branch, a loop body) or does nothing (a wait that never waits).
void check_mission_logic(const StaticCheckInput& in, Diagnostics& diags, const StaticCheckLimits& limits = {});

}  // namespace eamos::graph
