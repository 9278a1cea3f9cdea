#pragma once
// A picture of one run (the paper's Figure 3): the drones' tracks seen from above, and a
// timeline per drone with a bar per action, coloured by how it ended. Plain SVG text.
#include <string>
#include <vector>

#include "dex/runner.h"
#include "dex/trace.h"

namespace eamos::trace {

/// Top panel: each drone's track in the x/y plane (equal scale, metres), grey on the
/// ground, solid in the air, start labelled with the drone's name, a black square where
/// it armed, a green diamond where it landed, the failsafe's part dashed red, an orange ring
/// where it gave way to another drone and a dot where it flew on. Middle panel:
/// every drone's altitude over mission time. Bottom panel: one row per drone over mission
/// time, a bar per action start (`data-action` attribute) from start to end, coloured by
/// outcome; a labelled tick per condition decision (in lanes, never overlapping); each
/// wait for another drone's trigger (class "wait": who, on whom, how long) with an arrow
/// from the sender; each failsafe phase hatched red. `events` is the run's trace.
/// A problem to show on the picture (`eamos verify`): a red ring at (x, y) on the map and a
/// red line at mission time t across the timeline, both labelled.
struct PlotMark {
  double t = 0.0;
  double x = 0.0, y = 0.0;  ///< m, mission frame
  std::string label;        ///< "separation", ...
};

/// `caption`, when given, is a line under the title (which run of several this is).
std::string plot_svg(const dex::RunResult& run, const std::vector<dex::TraceEvent>& events,
                     const std::vector<PlotMark>& marks = {}, const std::string& caption = "");

}  // namespace eamos::trace
