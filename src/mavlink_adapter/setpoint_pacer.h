#pragma once
// The site's speed limits (fleet `safety:` max_speed, max_climb, max_descent) on a vehicle
// flown by position setpoints. An autopilot flies to a position setpoint at its own cruise
// speed (ArduPilot WPNAV_SPEED, PX4 MPC_XY_CRUISE), which the site may not allow; rather
// than change the vehicle's parameters, the adapter moves the setpoint it streams toward the
// goal no faster than the site allows, so the vehicle, chasing it, cannot fly faster. The
// same on every autopilot, and nothing on the vehicle is left changed after the mission.
#include "fleet/catalog.h"
#include "fleet/fleet.h"

namespace eamos::mavlink_adapter {

class SetpointPacer {
 public:
  /// `caps`: the limits to keep; `active` false sends every goal as it is.
  SetpointPacer(fleet::Limits caps, bool active) : caps_(caps), active_(active) {}
  /// A stream starts (again) with the vehicle at `vehicle`: the paced setpoint starts there.
  void restart(fleet::Vec3 vehicle) { carrot_ = vehicle; }
  /// The setpoint to stream now for `goal`, `dt` seconds after the previous one: the last
  /// one moved toward `goal` by at most what the caps allow in `dt`. A new goal (the next
  /// FlyTo, an orbit's moving point) is followed from where the last setpoint was, so the
  /// setpoints never jump.
  fleet::Vec3 next(fleet::Vec3 goal, double dt);

 private:
  fleet::Limits caps_;
  bool active_;
  fleet::Vec3 carrot_;
};

}  // namespace eamos::mavlink_adapter
