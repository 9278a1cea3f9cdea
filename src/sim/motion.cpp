#include "sim/motion.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "mid/vec.h"

namespace eamos::sim {

using fleet::Vec3;

double orbit_speed(double radius, const fleet::Limits& limits) {
  return std::min(limits.max_speed_mps, std::sqrt(0.8 * limits.max_accel_mps2 * radius));
}

namespace {

StepEvent step_orbit(Motion& m, mid::Kinematics& k, const fleet::Limits& limits, double dt) {
  if (!m.on_circle) {
    // Start on the circle's east point; the centre is where the orbit was started.
    Vec3 entry{m.target.x + m.radius, m.target.y, m.target.z};
    if (mid::move_toward(k, entry, limits, dt)) {
      m.on_circle = true;
      m.angle = 0.0;
      m.speed = 0.0;
    }
    return StepEvent::moving;
  }
  m.speed = std::min(orbit_speed(m.radius, limits), m.speed + 0.5 * limits.max_accel_mps2 * dt);
  m.angle = std::fmod(m.angle + m.speed * dt / m.radius, 2.0 * std::numbers::pi);
  double c = std::cos(m.angle), s = std::sin(m.angle);
  k.position = {m.target.x + m.radius * c, m.target.y + m.radius * s, m.target.z};
  k.velocity = {-m.speed * s, m.speed * c, 0.0};
  return StepEvent::moving;
}

}  // namespace

StepEvent step_motion(Motion& m, mid::Kinematics& k, const fleet::Limits& limits, double dt) {
  switch (m.kind) {
    case MotionKind::idle:
      return StepEvent::moving;
    case MotionKind::hold:
      if (!mid::move_toward(k, m.target, limits, dt)) return StepEvent::moving;
      m.kind = MotionKind::idle;
      return StepEvent::stopped;
    case MotionKind::go:
      if (!mid::move_toward(k, m.target, limits, dt)) return StepEvent::moving;
      if (m.land_after) {
        m.kind = MotionKind::land;
        m.target.z = m.ground_z;
        m.land_after = false;
        return StepEvent::moving;
      }
      m.kind = MotionKind::idle;
      return StepEvent::arrived;
    case MotionKind::land:
      if (!mid::move_toward(k, m.target, limits, dt)) return StepEvent::moving;
      m.kind = MotionKind::idle;
      return StepEvent::touched_down;
    case MotionKind::orbit:
      return step_orbit(m, k, limits, dt);
  }
  return StepEvent::moving;
}

double remaining_distance(const Motion& m, Vec3 position) {
  double d = norm(m.target - position);
  if (m.kind == MotionKind::go && m.land_after) d += std::max(0.0, m.target.z - m.ground_z);
  return d;
}

}  // namespace eamos::sim
