#pragma once
// What an action request means before any vehicle sees it: is it a capability of the drone's
// type with the right number of arguments, and where does a goal-directed motion end. Every
// adapter needs both, and they must agree with the compiler's catalog (fleet/catalog.h).
#include <optional>
#include <string>

#include "fleet/catalog.h"
#include "fleet/fleet.h"
#include "mid/drone_api.h"

namespace eamos::mid {

struct RequestCheck {
  const fleet::ActionSpec* spec = nullptr;  ///< the catalog entry; null when refused
  std::string error;                        ///< why it is refused; "" when accepted
};

/// Checks `request` against the type's capabilities and arities, and that every argument is
/// a finite number. The compiler checks the same for missions; this guards every other caller.
RequestCheck check_request(const ActionRequest& request, const fleet::DroneType& type);

/// Where a goal-directed motion action ends, from the drone's position when it starts:
/// Takeoff (straight up to ground + alt), Land (straight down to the ground), FlyTo, FlyBy,
/// FlyByX/Y/Z, ReturnHome (home, on the ground). The ground is at home.z (usually 0).
/// Empty for the others (Hover, Orbit, payload and system actions).
std::optional<fleet::Vec3> goal_position(const ActionRequest& request, fleet::Vec3 position,
                                         fleet::Vec3 home);

/// What the Uniform Space must know of a vehicle to judge a request by the rules every
/// adapter keeps (drone_api.h).
struct VehicleFacts {
  bool armed = false;
  bool landed = true;
  fleet::Vec3 position;         ///< where a relative motion would start from
  std::string running_motion;   ///< the name of the motion action running now; "" none
};

/// "" when `request` (already passed check_request, whose spec is `spec`) may start on a
/// vehicle in the state `v`, otherwise why not, in words: Disarm in the air or while a
/// motion runs, motion while disarmed, anything but Takeoff or Land on the ground, targets
/// below the ground or above max_altitude, non-positive radii and altitudes, targets outside
/// the drone's geofence (mid/site_limits.h). What only a
/// platform knows (battery, the autopilot's own checks) each adapter adds.
std::string uniform_refusal(const ActionRequest& request, const fleet::ActionSpec& spec, const VehicleFacts& v,
                            const fleet::DroneSettings& settings);

/// "12.3 m": how refusals print lengths.
std::string metres(double v);

}  // namespace eamos::mid
