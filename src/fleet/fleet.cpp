#include "fleet/fleet.h"

#include <algorithm>
#include <cmath>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include <sys/stat.h>

namespace eamos::fleet {

std::string signing_key_problem(const std::string& hex) {
  if (hex.size() != 64) return "a signing key is 64 hexadecimal digits (32 bytes), got " + std::to_string(hex.size()) +
                               " characters; make one with `openssl rand -hex 32`";
  if (hex.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos)
    return "a signing key holds only hexadecimal digits (0-9, a-f); make one with `openssl rand -hex 32`";
  if (hex.find_first_not_of('0') == std::string::npos)
    return "an all-zero signing key means \"signing off\" to an autopilot; make one with `openssl rand -hex 32`";
  return "";
}

std::string read_signing_key_file(const std::string& path, std::string& hex) {
  struct stat st{};
  if (stat(path.c_str(), &st) != 0) return "cannot read signing key file '" + path + "': " + std::strerror(errno);
  if (!S_ISREG(st.st_mode)) return "signing key file '" + path + "' is not a regular file";
  if ((st.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    return "signing key file '" + path + "' may be read or written by others (mode " + mode +
           "); whoever reads it can fly the vehicle: chmod 600 '" + path + "'";
  }
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  if (!in && !in.eof()) return "cannot read signing key file '" + path + "'";
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.pop_back();
  if (std::string why = signing_key_problem(text); !why.empty()) return "signing key file '" + path + "': " + why;
  hex = text;
  return "";
}


const char* failsafe_name(Failsafe f) {
  switch (f) {
    case Failsafe::land: return "land";
    case Failsafe::return_home: return "return_home";
    case Failsafe::hover: return "hover";
  }
  return "land";
}

void LimitOverrides::apply(Limits& limits) const {
  if (max_speed_mps) limits.max_speed_mps = *max_speed_mps;
  if (max_climb_mps) limits.max_climb_mps = *max_climb_mps;
  if (max_descent_mps) limits.max_descent_mps = *max_descent_mps;
  if (max_accel_mps2) limits.max_accel_mps2 = *max_accel_mps2;
  if (max_altitude_m) limits.max_altitude_m = *max_altitude_m;
}

DroneType Fleet::type_for(const std::string& type_name) const {
  auto it = types.find(type_name);
  return it != types.end() ? it->second : generic_multirotor(type_name);
}

DroneSettings Fleet::settings_for(const std::string& drone, const std::string& type_name,
                                  int index) const {
  DroneType type = type_for(type_name);
  DroneSettings s;
  auto it = drones.find(drone);
  if (it != drones.end()) s = it->second;
  const DroneOverrides* o = nullptr;
  if (auto oit = overrides.find(drone); oit != overrides.end()) o = &oit->second;

  s.name = drone;
  s.type = type_name;
  // Five metres apart along y keeps undescribed drones from starting on top of each other.
  if (!o || !o->home) s.home = {0.0, 5.0 * index, 0.0};
  if (!o || !o->adapter) s.adapter = type.adapter;
  s.limits = type.limits;
  s.tolerance = type.tolerance;
  s.home_tolerance_m = safety.home_tolerance_m;
  if (o) o->limits.apply(s.limits);
  if (const Geofence* g = geofence_for(drone)) s.site.geofence = *g;
  s.site.max_speed_mps = safety.max_speed_mps;
  s.site.max_climb_mps = safety.max_climb_mps;
  s.site.max_descent_mps = safety.max_descent_mps;
  // A sensor the type lacks can never be read (the checker rejects it); check_drone
  // reports it, and dropping it keeps the mission file to what the drone can do.
  std::erase_if(s.sensors, [&](const auto& kv) { return sensor_index(kv.first, type.sensors) == 0; });
  return s;
}

void Fleet::check_drone(const std::string& drone, const DroneType& type, Diagnostics& diags) const {
  auto it = overrides.find(drone);
  if (it == overrides.end()) return;
  for (const auto& [sensor, loc] : it->second.sensor_locations)
    if (sensor_index(sensor, type.sensors) == 0)
      diags.error(source.get(), loc,
                  "drone '" + drone + "' is of type '" + type.name + "', which has " +
                      std::to_string(type.sensors) + " sensors, so it has no " + sensor +
                      "; remove it or raise `sensors:` in type '" + type.name + "'");
}

bool Geofence::contains_xy(double x, double y) const {
  if (polygon.size() < 3) return true;
  // Even-odd rule; a point on an edge counts as inside, so a track along the fence is legal.
  bool inside = false;
  for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    auto [xi, yi] = polygon[i];
    auto [xj, yj] = polygon[j];
    double cross = (xj - xi) * (y - yi) - (yj - yi) * (x - xi);
    bool on_segment = std::abs(cross) < 1e-9 && x >= std::min(xi, xj) - 1e-9 && x <= std::max(xi, xj) + 1e-9 &&
                      y >= std::min(yi, yj) - 1e-9 && y <= std::max(yi, yj) + 1e-9;
    if (on_segment) return true;
    if ((yi > y) != (yj > y) && x < (xj - xi) * (y - yi) / (yj - yi) + xi) inside = !inside;
  }
  return inside;
}

bool Geofence::contains(double x, double y, double z) const {
  if (min_altitude_m && z < *min_altitude_m - 1e-9) return false;
  if (max_altitude_m && z > *max_altitude_m + 1e-9) return false;
  return contains_xy(x, y);
}

const Geofence* Fleet::geofence_for(const std::string& drone) const {
  auto it = overrides.find(drone);
  if (it != overrides.end() && it->second.geofence) return &*it->second.geofence;
  return safety.geofence ? &*safety.geofence : nullptr;
}

const SensorRange* Fleet::sensor_range(const std::string& drone, const std::string& sensor) const {
  auto it = overrides.find(drone);
  if (it == overrides.end()) return nullptr;
  auto r = it->second.sensor_ranges.find(sensor);
  return r == it->second.sensor_ranges.end() ? nullptr : &r->second;
}

bool load_fleet(const std::string& path, Fleet& out, Diagnostics& diags) {
  auto source = std::make_shared<SourceFile>();
  std::string error;
  if (!read_source_file(path, *source, error)) {
    diags.error(nullptr, {}, "cannot read fleet file '" + path + "': " + error +
                                 "; check the path given with --fleet");
    return false;
  }
  return parse_fleet(std::move(source), out, diags);
}

}  // namespace eamos::fleet
