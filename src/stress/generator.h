#pragma once
// Generates large, valid, warning-free missions for scaling tests (`eamos gen-stress`,
// bench/). Three shapes, each aimed at a path that could grow with the square of the fleet:
// - squads: squads of up to ten drones, each squad a sequence of parallel steps, with Ifs
//   and RepeatFor loops mixed into the steps (a survey or inspection fleet);
// - show: every drone in every PAR, FlyTo after FlyTo between fleet-wide barriers (a drone
//   show: the all-to-all boundary);
// - cross: squads whose drones wait on, branch on and fly to the positions of drones of
//   other squads (cross-drone conditions, waits and arguments).
// Every drone flies only along its own row (y = 5 · index, through its default home) and up
// and down, so the drones of a generated mission never come near each other: none has to
// give way in flight (dex/separation.h), and a run measures the executor, not a standoff.
#include <string>

namespace eamos::stress {

enum class Shape { squads, show, cross };
const char* shape_name(Shape s);
/// The shape named `name`; false when there is none.
bool shape_from_name(const std::string& name, Shape& out);

struct StressOptions {
  Shape shape = Shape::squads;
  long long target_nodes = 5000;  ///< stop adding steps once the MEG has about this many nodes
  int drones = 20;
  int squad_size = 10;            ///< drones per squad; squads synchronise only internally
  int work_per_step = 4;          ///< work items per drone between two squad barriers
  unsigned seed = 1;              ///< same seed, same text
};

/// Mission text; deterministic for given options.
std::string generate_mission(const StressOptions& options);

}  // namespace eamos::stress
