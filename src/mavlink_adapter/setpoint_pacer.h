#pragma once
// The site's speed limits (fleet `safety:` max_speed, max_climb, max_descent) on a vehicle
// flown by position setpoints. An autopilot flies to a position setpoint at its own cruise
// speed (ArduPilot WPNAV_SPEED, PX4 MPC_XY_CRUISE), which the site may not allow; rather
// than change the vehicle's parameters, the adapter moves the setpoint it streams toward the
// goal no faster than the site allows, so the vehicle, chasing it, cannot fly faster. The
// same on every autopilot, and nothing on the vehicle is left changed after the mission.
#include <optional>

#include "fleet/catalog.h"
#include "fleet/fleet.h"

namespace eamos::mavlink_adapter {

class SetpointPacer {
 public:
  /// `caps`: the limits to keep; `active` false sends every goal as it is.
  SetpointPacer(fleet::Limits caps, bool active) : caps_(caps), active_(active) {}
  /// The setpoint to stream now for `goal`, `dt` seconds after the previous one. A goal
  /// other than the last one starts the pacing again from `vehicle`, where the drone is.
  fleet::Vec3 next(fleet::Vec3 goal, fleet::Vec3 vehicle, double dt);

 private:
  fleet::Limits caps_;
  bool active_;
  std::optional<fleet::Vec3> goal_;
  fleet::Vec3 carrot_;
};

}  // namespace eamos::mavlink_adapter
