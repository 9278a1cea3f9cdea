#pragma once
// The Mover (paper, section VI): moves a point toward a target within a platform's limits,
// one time step at a time. The simulator flies every motion with it; the MAVLink adapter
// will use it to generate setpoints for manoeuvres the autopilot has no mode for (orbits).
#include "fleet/catalog.h"
#include "fleet/fleet.h"

namespace eamos::mid {

/// Where a moving point is and how fast it goes.
struct Kinematics {
  fleet::Vec3 position;  ///< m, mission frame
  fleet::Vec3 velocity;  ///< m/s
};

/// Advances `k` by `dt` seconds toward `target` and returns true once it is there (position
/// equal to target, velocity zero). Limits kept on every step:
///  - horizontal speed <= max_speed, vertical speed <= max_climb up and max_descent down;
///  - the velocity changes by at most max_accel·dt per step (so turns and stops are smooth);
///  - it brakes in time: the speed toward the target never exceeds sqrt(2·max_accel·distance).
/// Within one step of the target it snaps onto it, so "fly by 5 m" ends exactly 5 m away.
bool move_toward(Kinematics& k, fleet::Vec3 target, const fleet::Limits& limits, double dt);

/// The fastest velocity along `direction` (any length, not zero) that keeps the speed limits.
fleet::Vec3 limited_velocity(fleet::Vec3 direction, double speed, const fleet::Limits& limits);

}  // namespace eamos::mid
