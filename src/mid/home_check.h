#pragma once
// The check that the vehicles stand where the fleet file says, before anything arms. Each
// adapter ties the mission frame to its vehicle at the drone's declared `home` (MAVLink: the
// vehicle's local origin is put there), so a home that is wrong shifts everything that
// drone flies: routes that should be apart cross. Vehicles that know where they are on the
// Earth (GPS) are compared with each other: the metres east and north between two of them
// must be the metres between their declared homes, within the fleet's `home_tolerance`.
#include <optional>
#include <string>
#include <vector>

#include "fleet/fleet.h"
#include "mid/drone_api.h"
#include "mid/event_loop.h"

namespace eamos::mid {

/// How long (wall seconds) the check waits for the vehicles' first global positions.
inline constexpr double kHomeFixTimeoutS = 5.0;

/// One drone at connect: its declared home and, when its vehicle reports one, where it
/// stands on the Earth.
struct HomeReport {
  std::string drone;
  fleet::Vec3 home;                ///< declared, mission frame
  std::optional<GlobalFix> fix;    ///< reported; empty: the vehicle has no global position
  double tolerance_m = fleet::kDefaultHomeToleranceM;
};

/// "" when every pair of drones with a fix stands as their homes are declared, within the
/// larger of their tolerances; else one line per drone that does not, naming its declared
/// home, where it stands in the mission frame and on the Earth, and the fix. The drone the
/// others are measured from is the one most of the others agree with (the first declared on
/// a tie): with one vehicle misplaced, that vehicle is named, not every other.
std::string compare_homes(const std::vector<HomeReport>& drones);

/// Runs `loop` (which takes the vehicles' frames), up to `timeout_s` wall seconds, until every
/// drone with a global frame has a fix.
void wait_for_fixes(EventLoop& loop, const std::vector<Drone*>& drones, double timeout_s);

/// wait_for_fixes, then compare_homes over the drones with a fix. Drones without a global
/// frame (the built-in simulator) are left out; with fewer than two to compare it returns
/// "" at once.
std::string check_homes_at_connect(EventLoop& loop, const std::vector<Drone*>& drones,
                                   const std::vector<fleet::DroneSettings>& settings, double timeout_s);

}  // namespace eamos::mid
