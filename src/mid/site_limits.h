#pragma once
// The site's rules (fleet `safety:`, a drone's own `geofence:`) as every adapter's drone keeps
// them in flight: the target of an action outside the geofence or its altitude band is
// refused before the vehicle moves; a drone found outside it anyway is a fault; and the
// site's speed limits cap the vehicle's. One place, so the simulator and the MAVLink adapter
// (and therefore `eamos run`, every DEX and `eamos verify`'s own checks) agree.
#include <string>

#include "fleet/fleet.h"
#include "mid/drone_api.h"
#include "mid/requests.h"

namespace eamos::mid {

/// "" when `r` keeps to the drone's geofence, otherwise why not, naming the target and the
/// rule it breaks and how to fix it. Checks the goal of every goal-directed motion but Land
/// and ReturnHome (down is always allowed; home is where the drone took off), the straight
/// path to it (a concave fence can lie between two inside points), and an Orbit's circle.
/// `min_altitude` does not apply to Takeoff, which starts below it.
std::string fence_refusal(const ActionRequest& r, const VehicleFacts& v, const fleet::DroneSettings& s);

/// "" while `s` lies inside `fence`, otherwise which rule it breaks at which position.
/// `below_min_allowed`: a takeoff or landing, when `min_altitude` does not apply.
std::string fence_breach(const fleet::Geofence& fence, const DroneState& s, bool below_min_allowed);

/// The limits the vehicle flies with: its own (`s.limits`), each capped by the site's.
fleet::Limits flight_limits(const fleet::DroneSettings& s);

/// "(12.0, -3.5, 10.0)": how refusals print a position.
std::string position_text(fleet::Vec3 p);

}  // namespace eamos::mid
