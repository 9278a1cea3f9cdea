#include "mid/home_check.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace eamos::mid {
namespace {

constexpr double kEarthRadiusM = 6'371'000.0;
constexpr double kRadPerDegree = M_PI / 180.0;

/// Metres (east, north) from `a` to `b`: flat earth, which over a field errs by far less
/// than GPS does.
std::pair<double, double> east_north(const GlobalFix& a, const GlobalFix& b) {
  double mid_lat = (a.lat_deg + b.lat_deg) / 2.0 * kRadPerDegree;
  return {(b.lon_deg - a.lon_deg) * kRadPerDegree * kEarthRadiusM * std::cos(mid_lat),
          (b.lat_deg - a.lat_deg) * kRadPerDegree * kEarthRadiusM};
}

std::string num(double v, const char* format = "%.1f") {
  char buf[48];
  std::snprintf(buf, sizeof buf, format, v);
  std::string s = buf;
  return s == "-0.0" ? "0.0" : s;
}

/// How far `d` stands from where its home says, measured from `ref` at its home.
double mismatch(const HomeReport& ref, const HomeReport& d, double& x, double& y) {
  auto [east, north] = east_north(*ref.fix, *d.fix);
  x = ref.home.x + east;
  y = ref.home.y + north;
  return std::hypot(x - d.home.x, y - d.home.y);
}

bool agrees(const HomeReport& ref, const HomeReport& d) {
  double x = 0, y = 0;
  return mismatch(ref, d, x, y) <= std::max(ref.tolerance_m, d.tolerance_m);
}

std::string line_for(const HomeReport& ref, const HomeReport& d) {
  double x = 0, y = 0;
  double off = mismatch(ref, d, x, y);
  double tolerance = std::max(ref.tolerance_m, d.tolerance_m);
  return d.drone + " stands at [" + num(x) + ", " + num(y) + "] in the mission frame (lat " + num(d.fix->lat_deg, "%.7f") +
         ", lon " + num(d.fix->lon_deg, "%.7f") + "; measured from " + ref.drone + " at its home [" + num(ref.home.x) +
         ", " + num(ref.home.y) + "]), but its home in the fleet file is [" + num(d.home.x) + ", " + num(d.home.y) +
         "]: " + num(off) + " m apart, more than home_tolerance " + num(tolerance, "%g") + " m; place the vehicle at its " +
         "home, or write the home where it stands (home: [" + num(x) + ", " + num(y) + ", " + num(d.home.z, "%g") + "])";
}

}  // namespace

std::string compare_homes(const std::vector<HomeReport>& drones) {
  std::vector<const HomeReport*> fixed;
  for (const HomeReport& d : drones)
    if (d.fix) fixed.push_back(&d);
  if (fixed.size() < 2) return "";
  const HomeReport* ref = fixed[0];
  std::size_t best = 0;
  for (const HomeReport* r : fixed) {
    std::size_t n = std::count_if(fixed.begin(), fixed.end(), [&](const HomeReport* d) { return agrees(*r, *d); });
    if (n > best) {
      best = n;
      ref = r;
    }
  }
  std::string out;
  for (const HomeReport* d : fixed)
    if (!agrees(*ref, *d)) out += (out.empty() ? "" : "\n") + line_for(*ref, *d);
  return out;
}

void wait_for_fixes(EventLoop& loop, const std::vector<Drone*>& drones, double timeout_s) {
  auto missing = [&] {
    return std::any_of(drones.begin(), drones.end(), [](Drone* d) { return d->has_global_frame() && !d->global_fix(); });
  };
  // The loop takes the frames the links post; mission time runs meanwhile, so a mission on
  // MAVLink starts the instant its fixes are in rather than at 0.
  auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (missing() && std::chrono::steady_clock::now() < until) loop.run_until(loop.now() + 0.05);
}

std::string check_homes_at_connect(EventLoop& loop, const std::vector<Drone*>& drones,
                                   const std::vector<fleet::DroneSettings>& settings, double timeout_s) {
  std::size_t global = std::count_if(drones.begin(), drones.end(), [](Drone* d) { return d->has_global_frame(); });
  if (global < 2) return "";
  wait_for_fixes(loop, drones, timeout_s);
  std::vector<HomeReport> reports;
  for (std::size_t i = 0; i < drones.size() && i < settings.size(); ++i)
    reports.push_back({settings[i].name, settings[i].home, drones[i]->global_fix(), settings[i].home_tolerance_m});
  return compare_homes(reports);
}

}  // namespace eamos::mid
