#pragma once
// What the simulated vehicle is doing with its motors: one motion at a time, advanced one
// fixed time step at a time by step_motion. Plain data, so the drone can swap motions when a
// new action preempts the old one (the velocity carries over: turns stay smooth).
#include "fleet/catalog.h"
#include "fleet/fleet.h"
#include "mid/mover.h"

namespace eamos::sim {

enum class MotionKind {
  idle,   ///< standing still (on the ground or in the air): no steps needed
  hold,   ///< braking to a stop at `target` (a cancelled motion, Hover while moving)
  go,     ///< flying to `target` (Takeoff, FlyTo, FlyBy*, first leg of ReturnHome)
  land,   ///< descending straight down to `target` (z = ground)
  orbit,  ///< flying out to the circle around `target`, then around it for ever
};

struct Motion {
  MotionKind kind = MotionKind::idle;
  fleet::Vec3 target;          ///< where it stops; orbit: the centre
  bool land_after = false;     ///< go: switch to land on arrival (ReturnHome)
  double ground_z = 0.0;       ///< land, land_after: height of the ground
  double radius = 0.0;         ///< orbit: m
  bool on_circle = false;      ///< orbit: reached the circle, now going round
  double angle = 0.0;          ///< orbit: position on the circle, rad from east, counter-clockwise
  double speed = 0.0;          ///< orbit: current speed along the circle, m/s
  double start_distance = 0.0; ///< path length when it started, for progress
};

enum class StepEvent {
  moving,        ///< nothing to report
  stopped,       ///< hold reached its point; the motion is idle now
  arrived,       ///< go reached its target; the motion is idle now
  touched_down,  ///< land reached the ground; the motion is idle now
};

/// Advances `k` by `dt` seconds within `limits`.
StepEvent step_motion(Motion& m, mid::Kinematics& k, const fleet::Limits& limits, double dt);

/// Path length still to fly for hold, go and land (a ReturnHome's first leg counts its descent).
double remaining_distance(const Motion& m, fleet::Vec3 position);

/// The steady speed around a circle of `radius`: at most max_speed, and slow enough that the
/// centripetal acceleration stays within 80 % of max_accel (the rest is left for speeding up
/// along the circle at half of max_accel, so the total stays below max_accel).
double orbit_speed(double radius, const fleet::Limits& limits);

}  // namespace eamos::sim
