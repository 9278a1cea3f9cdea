#include "mavlink_adapter/setpoint_pacer.h"

#include <algorithm>
#include <cmath>

namespace eamos::mavlink_adapter {

fleet::Vec3 SetpointPacer::next(fleet::Vec3 goal, double dt) {
  if (!active_) return goal;
  double dx = goal.x - carrot_.x, dy = goal.y - carrot_.y, dz = goal.z - carrot_.z;
  double horizontal = std::hypot(dx, dy);
  double step = caps_.max_speed_mps * dt;
  if (horizontal <= step) {
    carrot_.x = goal.x, carrot_.y = goal.y;
  } else {
    carrot_.x += dx / horizontal * step, carrot_.y += dy / horizontal * step;
  }
  double vertical = (dz > 0 ? caps_.max_climb_mps : caps_.max_descent_mps) * dt;
  carrot_.z = std::abs(dz) <= vertical ? goal.z : carrot_.z + std::copysign(vertical, dz);
  return carrot_;
}

}  // namespace eamos::mavlink_adapter
