#pragma once
// The "literal altitude outside the drone's band" rule: a Takeoff or FlyTo whose altitude is
// written as a number above the drone's `max_altitude` (its limits, or its geofence), or not
// above the ground (a Takeoff to 0 m, a FlyTo to z at or below its home's), is refused by the
// drone at run time; `eamos check` reports it at the argument instead.
#include "diag/diagnostics.h"
#include "fleet/fleet.h"
#include "lang/ast.h"

namespace eamos::lang {

/// An error at each Takeoff(alt) whose literal alt is above the drone's limits'
/// max_altitude (metres over its home), and each Takeoff or FlyTo whose literal target z
/// is above that or above its geofence's max_altitude (z of the mission frame), and each
/// Takeoff(alt) with alt <= 0 or FlyTo whose literal z is not above its home's z; a note
/// points at the fleet file's max_altitude when the file sets it. `settings_made`, when
/// given, receives how many drones' settings that needed (at most one per drone).
void check_literal_altitudes(const Mission& mission, const fleet::Fleet& fleet, Diagnostics& diags,
                             int* settings_made = nullptr);

}  // namespace eamos::lang
