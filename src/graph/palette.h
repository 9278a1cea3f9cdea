#pragma once
// One colour per drone, the same in every picture (`eamos graph`, `--plot`, the monitor):
// the eight colour-blind-safe Okabe–Ito colours first, then hues a golden angle apart (in
// two lightnesses), so a fleet of more than eight drones does not repeat a colour.
#include <string>

namespace eamos::graph {

/// "#RRGGBB" for drone `d` (index in declaration order); grey for d < 0 (no drone).
std::string drone_colour(int d);

}  // namespace eamos::graph
