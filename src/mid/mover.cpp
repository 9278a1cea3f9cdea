#include "mid/mover.h"

#include <algorithm>
#include <cmath>

#include "mid/vec.h"

namespace eamos::mid {

using fleet::Vec3;

Vec3 limited_velocity(Vec3 direction, double speed, const fleet::Limits& limits) {
  double length = norm(direction);
  if (length <= 0.0 || speed <= 0.0) return {};
  Vec3 v = direction * (speed / length);
  // Scale the whole vector down (not each axis apart) so the direction is kept.
  double scale = 1.0;
  double h = horizontal_norm(v);
  if (h > limits.max_speed_mps) scale = std::min(scale, limits.max_speed_mps / h);
  if (v.z > limits.max_climb_mps) scale = std::min(scale, limits.max_climb_mps / v.z);
  if (-v.z > limits.max_descent_mps) scale = std::min(scale, limits.max_descent_mps / -v.z);
  return v * scale;
}

bool move_toward(Kinematics& k, Vec3 target, const fleet::Limits& limits, double dt) {
  Vec3 to_target = target - k.position;
  double distance = norm(to_target);
  double speed = norm(k.velocity);
  // Close enough that this step would reach it: land on the target exactly.
  if (distance <= std::max(speed * dt, 1e-9) &&
      speed <= limits.max_accel_mps2 * dt + std::sqrt(2.0 * limits.max_accel_mps2 * distance)) {
    k.position = target;
    k.velocity = {};
    return true;
  }
  // The fastest speed from which braking at max_accel, one step at a time, still stops at
  // the target: v·dt/2 + v²/(2a) = distance. (The continuous sqrt(2·a·d) overshoots, because
  // a step moves at its new speed for the whole dt.)
  double half_step = 0.5 * limits.max_accel_mps2 * dt;
  double braking_speed =
      std::sqrt(half_step * half_step + 2.0 * limits.max_accel_mps2 * distance) - half_step;
  Vec3 desired = limited_velocity(to_target, braking_speed, limits);
  Vec3 change = desired - k.velocity;
  double change_norm = norm(change);
  double max_change = limits.max_accel_mps2 * dt;
  if (change_norm > max_change) change = change * (max_change / change_norm);
  // Both the old and the desired velocity keep the speed limits, and the limits form a convex
  // set, so every velocity between them does too.
  k.velocity = k.velocity + change;
  k.position = k.position + k.velocity * dt;
  return false;
}

}  // namespace eamos::mid
