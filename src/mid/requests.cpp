#include "mid/requests.h"

#include "mid/site_limits.h"

#include <cstdio>

#include <algorithm>
#include <cmath>

namespace eamos::mid {

RequestCheck check_request(const ActionRequest& request, const fleet::DroneType& type) {
  const fleet::ActionSpec* spec = type.find_action(request.name);
  if (!spec)
    return {nullptr, "type '" + type.name + "' has no action '" + request.name + "'"};
  int n = static_cast<int>(request.args.size());
  if (std::find(spec->arities.begin(), spec->arities.end(), n) == spec->arities.end())
    return {nullptr, request.name + " takes (" + spec->params + "), not " + std::to_string(n) +
                         " argument" + (n == 1 ? "" : "s")};
  for (double a : request.args)
    if (!std::isfinite(a)) return {nullptr, request.name + " got an argument that is not a finite number"};
  return {spec, ""};
}

std::optional<fleet::Vec3> goal_position(const ActionRequest& r, fleet::Vec3 p, fleet::Vec3 home) {
  const auto& a = r.args;
  if (r.name == "Takeoff" && a.size() == 1) return fleet::Vec3{p.x, p.y, home.z + a[0]};
  if (r.name == "Land") return fleet::Vec3{p.x, p.y, home.z};
  if (r.name == "FlyTo" && a.size() == 3) return fleet::Vec3{a[0], a[1], a[2]};
  if (r.name == "FlyBy" && a.size() == 3) return fleet::Vec3{p.x + a[0], p.y + a[1], p.z + a[2]};
  if (r.name == "FlyByX" && a.size() == 1) return fleet::Vec3{p.x + a[0], p.y, p.z};
  if (r.name == "FlyByY" && a.size() == 1) return fleet::Vec3{p.x, p.y + a[0], p.z};
  if (r.name == "FlyByZ" && a.size() == 1) return fleet::Vec3{p.x, p.y, p.z + a[0]};
  if (r.name == "ReturnHome") return home;
  return std::nullopt;
}

std::string metres(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f m", v);
  return buf;
}

std::string uniform_refusal(const ActionRequest& r, const fleet::ActionSpec& spec, const VehicleFacts& v,
                            const fleet::DroneSettings& settings) {
  const auto& a = r.args;
  const double ground_z = settings.home.z;
  if (r.name == "Disarm") {
    if (!v.landed) return "in the air at z = " + metres(v.position.z) + ": land before disarming";
    if (!v.running_motion.empty()) return v.running_motion + " is running: cannot disarm";
  }
  if (spec.action_class != fleet::ActionClass::motion) return "";
  if (!v.armed) return "disarmed: arm before " + r.name;
  if (r.name == "Takeoff") {
    if (a[0] <= 0.0) return "takeoff altitude must be positive, got " + metres(a[0]);
    if (a[0] > settings.limits.max_altitude_m)
      return "takeoff altitude " + metres(a[0]) + " is above max_altitude " + metres(settings.limits.max_altitude_m);
    return fence_refusal(r, v, settings);
  }
  if (r.name == "Land") return "";
  if (v.landed) return "on the ground: take off before " + r.name;
  if (r.name == "Orbit" && a.size() == 1 && a[0] <= 0.0) return "orbit radius must be positive, got " + metres(a[0]);
  if (r.name == "Hover" && a.size() == 1 && a[0] < 0.0) return "hover duration must not be negative";
  if (r.name == "ReturnHome") return "";
  if (auto goal = goal_position(r, v.position, settings.home)) {
    if (goal->z <= ground_z)
      return "target z = " + metres(goal->z) + " is not above the ground (z = " + metres(ground_z) +
             "); use Land to land";
    if (goal->z > ground_z + settings.limits.max_altitude_m)
      return "target z = " + metres(goal->z) + " is above max_altitude " + metres(settings.limits.max_altitude_m) +
             " over the ground";
  }
  return fence_refusal(r, v, settings);
}

}  // namespace eamos::mid
