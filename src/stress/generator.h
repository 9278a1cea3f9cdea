#pragma once
// Generates large, valid, warning-free missions for scaling tests (`eamos gen-stress`,
// bench/). The shape mirrors a real fleet operation: squads of up to ten drones, each
// squad a sequence of parallel steps, with Ifs and RepeatFor loops mixed into the steps.
#include <string>

namespace eamos::stress {

struct StressOptions {
  long long target_nodes = 5000;  ///< stop adding steps once the MEG has about this many nodes
  int drones = 20;
  int squad_size = 10;            ///< drones per squad; squads synchronise only internally
  int work_per_step = 4;          ///< work items per drone between two squad barriers
  unsigned seed = 1;              ///< same seed, same text
};

/// Mission text; deterministic for given options.
std::string generate_mission(const StressOptions& options);

}  // namespace eamos::stress
