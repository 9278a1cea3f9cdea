#pragma once
// One colour per drone, the same in every picture (`eamos graph`, `--plot`, the monitor's
// page, which has no rule of its own and takes drone_palette from the server):
// the eight colour-blind-safe Okabe–Ito colours first, then hues a golden angle apart (in
// two lightnesses), so a fleet of more than eight drones does not repeat a colour.
#include <string>
#include <vector>

namespace eamos::graph {

/// "#RRGGBB" for drone `d` (index in declaration order); grey for d < 0 (no drone).
std::string drone_colour(int d);
/// drone_colour(0) .. drone_colour(count - 1).
std::vector<std::string> drone_palette(int count);

}  // namespace eamos::graph
