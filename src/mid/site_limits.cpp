#include "mid/site_limits.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace eamos::mid {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Orientation of (a, b, c): positive counter-clockwise, negative clockwise, 0 collinear.
double orient(std::pair<double, double> a, std::pair<double, double> b, std::pair<double, double> c) {
  return (b.first - a.first) * (c.second - a.second) - (b.second - a.second) * (c.first - a.first);
}

/// True when the straight path a → b crosses an edge of the polygon properly (a concave
/// fence between two inside points). Touching an edge or a corner stays inside.
bool path_crosses(const fleet::Geofence& g, fleet::Vec3 a, fleet::Vec3 b) {
  const auto& p = g.polygon;
  if (p.size() < 3) return false;
  std::pair<double, double> pa{a.x, a.y}, pb{b.x, b.y};
  for (std::size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) {
    double d1 = orient(p[j], p[i], pa), d2 = orient(p[j], p[i], pb);
    double d3 = orient(pa, pb, p[j]), d4 = orient(pa, pb, p[i]);
    if (((d1 > 1e-9 && d2 < -1e-9) || (d1 < -1e-9 && d2 > 1e-9)) &&
        ((d3 > 1e-9 && d4 < -1e-9) || (d3 < -1e-9 && d4 > 1e-9)))
      return true;
  }
  return false;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

std::string polygon_text(const fleet::Geofence& g) {
  double x0 = g.polygon[0].first, x1 = x0, y0 = g.polygon[0].second, y1 = y0;
  for (auto [x, y] : g.polygon) {
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  }
  return "its polygon of " + std::to_string(g.polygon.size()) + " corners (x " + number(x0) + " to " + number(x1) +
         ", y " + number(y0) + " to " + number(y1) + ")";
}

/// Which rule of `g` the point `p` breaks, "" when none.
std::string broken_rule(const fleet::Geofence& g, fleet::Vec3 p, bool below_min_allowed) {
  if (!g.contains_xy(p.x, p.y)) return "outside " + polygon_text(g);
  if (g.max_altitude_m && p.z > *g.max_altitude_m + 1e-9) return "above its max_altitude " + metres(*g.max_altitude_m);
  if (!below_min_allowed && g.min_altitude_m && p.z < *g.min_altitude_m - 1e-9)
    return "below its min_altitude " + metres(*g.min_altitude_m);
  return "";
}

std::string refused(const ActionRequest& r, const std::string& name, fleet::Vec3 target, const std::string& rule) {
  return name + " " + r.name + ": target " + position_text(target) + " is " + rule + " of " + name +
         "'s geofence; keep the target inside it, or widen `geofence:` in the fleet file";
}

}  // namespace

std::string position_text(fleet::Vec3 p) { return "(" + number(p.x) + ", " + number(p.y) + ", " + number(p.z) + ")"; }

std::string fence_refusal(const ActionRequest& r, const VehicleFacts& v, const fleet::DroneSettings& s) {
  if (!s.site.geofence || r.name == "Land" || r.name == "ReturnHome") return "";
  const fleet::Geofence& g = *s.site.geofence;
  if (r.name == "Orbit") {
    double radius = r.args.empty() ? 5.0 : r.args[0];
    for (int k = 0; k < 32; ++k) {
      double a = 2.0 * kPi * k / 32.0;
      fleet::Vec3 p{v.position.x + radius * std::cos(a), v.position.y + radius * std::sin(a), v.position.z};
      if (std::string rule = broken_rule(g, p, false); !rule.empty())
        return s.name + " Orbit: its circle of radius " + metres(radius) + " around " + position_text(v.position) +
               " passes " + position_text(p) + ", " + rule + " of " + s.name +
               "'s geofence; orbit with a smaller radius or further inside";
    }
    return "";
  }
  std::optional<fleet::Vec3> goal = goal_position(r, v.position, s.home);
  if (!goal) return "";
  if (std::string rule = broken_rule(g, *goal, r.name == "Takeoff"); !rule.empty())
    return refused(r, s.name, *goal, rule);
  if (path_crosses(g, v.position, *goal))
    return refused(r, s.name, *goal, "inside, but the straight path from " + position_text(v.position) +
                                         " to it leaves " + polygon_text(g) + ",");
  return "";
}

std::string fence_breach(const fleet::Geofence& fence, const DroneState& s, bool below_min_allowed) {
  fleet::Vec3 p{s.x, s.y, s.z};
  std::string rule = broken_rule(fence, p, below_min_allowed);
  return rule.empty() ? "" : "at " + position_text(p) + ", " + rule;
}

fleet::Limits flight_limits(const fleet::DroneSettings& s) {
  fleet::Limits l = s.limits;
  if (s.site.max_speed_mps) l.max_speed_mps = std::min(l.max_speed_mps, *s.site.max_speed_mps);
  if (s.site.max_climb_mps) l.max_climb_mps = std::min(l.max_climb_mps, *s.site.max_climb_mps);
  if (s.site.max_descent_mps) l.max_descent_mps = std::min(l.max_descent_mps, *s.site.max_descent_mps);
  return l;
}

}  // namespace eamos::mid
