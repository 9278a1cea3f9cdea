#include "mid/requests.h"

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

}  // namespace eamos::mid
