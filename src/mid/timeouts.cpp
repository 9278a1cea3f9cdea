#include "mid/timeouts.h"

#include <cmath>
#include <limits>

#include "mid/requests.h"
#include "mid/vec.h"

namespace eamos::mid {

bool is_endless(const ActionRequest& r) {
  return (r.name == "Hover" && r.args.empty()) || r.name == "Orbit";
}

double expected_duration(const ActionRequest& r, fleet::Vec3 position,
                         const fleet::DroneSettings& drone) {
  if (is_endless(r)) return std::numeric_limits<double>::infinity();
  if (r.name == "Hover" && r.args.size() == 1) return std::max(0.0, r.args[0]);
  auto goal = goal_position(r, position, drone.home);
  if (!goal) return 0.0;
  const fleet::Limits& l = drone.limits;
  fleet::Vec3 d = *goal - position;
  double vertical_speed = d.z > 0 ? l.max_climb_mps : l.max_descent_mps;
  // The sum, not the maximum, of the two legs: ReturnHome flies them one after the other,
  // and for the others it only adds margin.
  return horizontal_norm(d) / l.max_speed_mps + std::abs(d.z) / vertical_speed;
}

double action_timeout(const ActionRequest& r, fleet::Vec3 position,
                      const fleet::DroneSettings& drone) {
  if (is_endless(r)) return std::numeric_limits<double>::infinity();
  if (auto it = drone.timeouts_s.find(r.name); it != drone.timeouts_s.end()) return it->second;
  return expected_duration(r, position, drone) * kTimeoutMargin + kTimeoutSlack_s;
}

}  // namespace eamos::mid
