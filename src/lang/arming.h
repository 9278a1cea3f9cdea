#pragma once
// The "motion action while disarmed" rule: a drone refuses every motion action until it is
// armed, so a Takeoff that can run before the drone's Arm() fails the flight at run time.
// The rule follows each drone's Armed state through the mission as a set of what it may be
// (armed, disarmed) and reports the motion actions it may reach disarmed.
#include <vector>

#include "diag/diagnostics.h"
#include "fleet/catalog.h"
#include "lang/ast.h"

namespace eamos::lang {

/// An error at a motion action that runs while its drone is disarmed on every path that
/// reaches it, a warning at one that may run disarmed on some paths only (a branch that
/// skips the Arm, a Disarm in a loop or a parallel branch). Branches, loops, PAR siblings,
/// async work and cancelled Do-branches are all taken into account; a failed action ends
/// the path it fails on, so only the first action of a path that runs disarmed is reported.
/// Each drone visits only the statements that mention it (directly or through the blocks
/// they call): `work`, when given, receives how many statement visits that took over all
/// drones, the figure that stays linear in the mission whatever its shape.
void check_armed_before_motion(const Mission& mission, const std::vector<fleet::DroneType>& types,
                               Diagnostics& diags, long long* work = nullptr);

}  // namespace eamos::lang
