// parse_fleet: the fleet file's schema (docs/fleet.md), one function per map in it.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>

#include "diag/number.h"
#include "fleet/fleet.h"
#include "fleet/link_url.h"
#include "fleet/yaml_reader.h"

namespace eamos::fleet {

namespace {

const std::vector<std::string> kRootKeys = {"types", "drones", "safety"};
const std::vector<std::string> kSafetyKeys = {"min_separation", "battery_reserve", "max_speed",
                                              "max_climb",      "max_descent",     "geofence",
                                              "home_tolerance"};
const std::vector<std::string> kSeparationKeys = {"horizontal", "vertical"};
const std::vector<std::string> kGeofenceKeys = {"polygon", "min_altitude", "max_altitude", "upload"};
const std::vector<std::string> kTypeKeys = {"adapter", "capabilities", "sensors", "limits", "tolerance"};
const std::vector<std::string> kToleranceKeys = {"horizontal", "vertical", "speed"};
const std::vector<std::string> kDroneKeys = {"home",     "battery",  "sensors",
                                             "limits",   "failsafe", "adapter",
                                             "connection", "sysid",  "timeouts",
                                             "geofence", "signing",  "announce_as_gcs",
                                             "gust",
                                             "priority"};
const std::vector<std::string> kGustKeys = {"at", "for", "velocity"};
const std::vector<std::string> kSigningKeys = {"key", "key_file", "setup"};
const std::vector<std::string> kLimitKeys = {"max_speed", "max_climb", "max_descent",
                                             "max_accel", "max_altitude"};
const std::vector<std::string> kSensorKeys = {"value", "gradient", "range"};
const std::vector<std::string> kAdapters = {"sim", "mavlink"};
const std::vector<std::string> kFailsafes = {"land", "return_home", "hover"};

std::vector<std::string> standard_action_names() {
  std::vector<std::string> names;
  for (const auto& a : standard_actions()) names.push_back(a.name);
  return names;
}

bool is_standard_property(const std::string& name) {
  const auto& props = standard_properties();
  return std::any_of(props.begin(), props.end(), [&](const PropertySpec& p) { return p.name == name; });
}

Failsafe failsafe_from(const std::string& name) {
  if (name == "return_home") return Failsafe::return_home;
  if (name == "hover") return Failsafe::hover;
  return Failsafe::land;
}

class FleetParser {
 public:
  FleetParser(const SourceFile* file, Fleet& out, Diagnostics& diags)
      : r_{file, diags}, out_(out) {}
  void parse(const YAML::Node& root);

 private:
  void types(const YAML::Node& node);
  void type(const std::string& name, const YAML::Node& node);
  void capabilities(const YAML::Node& node, const std::string& where, DroneType& type);
  void limits(const YAML::Node& node, const std::string& where, LimitOverrides& out);
  void drones(const YAML::Node& node);
  void drone(const std::string& name, const YAML::Node& node);
  void sensors(const YAML::Node& node, const std::string& where, DroneSettings& settings,
               DroneOverrides& overrides);
  void sensor(const YAML::Node& node, const std::string& what, SensorModel& out,
              std::optional<SensorRange>& range);
  void range(const YAML::Node& node, const std::string& what, std::optional<SensorRange>& out);
  void safety(const YAML::Node& node);
  void check_connection(const YAML::Node& node, const std::string& what, const std::string& url);
  void separation(const YAML::Node& node, Separation& out);
  void tolerance(const YAML::Node& node, const std::string& where, GoalTolerance& out);
  /// A map of positive numbers, `keys[k]` read into `*fields[k]` (`shape` shows the map in
  /// the error for a node that is not one).
  void positive_fields(const YAML::Node& node, const std::string& what, const std::string& shape,
                       const std::vector<std::string>& keys, const std::vector<double*>& fields);
  bool positive(const YAML::Node& node, const std::string& what, double& out);
  void geofence(const YAML::Node& node, const std::string& where, std::optional<Geofence>& out);
  void polygon(const YAML::Node& node, const std::string& what, Geofence& out);
  void timeouts(const YAML::Node& node, const std::string& where, DroneSettings& settings);
  void signing(const YAML::Node& node, const std::string& where, DroneSettings& settings);
  bool flag(const YAML::Node& node, const std::string& what, bool& out);
  void gust(const YAML::Node& node, const std::string& what, std::optional<Gust>& out);
  bool saturated() const { return r_.diags.saturated(); }

  YamlReader r_;
  Fleet& out_;
  /// The most sensors any type a drone may turn out to have: the generic 8 or a described
  /// type's count. The drone's own type is known only once a mission names it.
  int max_sensors_ = 8;
};

void FleetParser::parse(const YAML::Node& root) {
  if (!r_.map(root, "the fleet file")) return;
  // Types first wherever they are written: a drone's sensors are checked against them.
  std::optional<YAML::Node> types_node, drones_node, safety_node;
  std::set<std::string> seen;
  for (const auto& kv : root) {
    std::string key = r_.field(kv.first, kRootKeys, seen, "the fleet file");
    if (key == "types") types_node = kv.second;
    if (key == "drones") drones_node = kv.second;
    if (key == "safety") safety_node = kv.second;
  }
  if (types_node) types(*types_node);
  if (drones_node) drones(*drones_node);
  if (safety_node) safety(*safety_node);
}

void FleetParser::types(const YAML::Node& node) {
  if (!r_.map(node, "types")) return;
  std::set<std::string> seen;
  for (const auto& kv : node) {
    if (saturated()) return;
    std::string name = r_.name(kv.first, seen, "types");
    if (!name.empty()) type(name, kv.second);
  }
}

void FleetParser::type(const std::string& name, const YAML::Node& node) {
  DroneType t = generic_multirotor(name);
  t.generic = false;
  long long sensor_count = t.sensors;
  const std::string where = "type '" + name + "'";
  std::set<std::string> seen;
  if (r_.map(node, where)) {
    for (const auto& kv : node) {
      std::string key = r_.field(kv.first, kTypeKeys, seen, where);
      const YAML::Node& v = kv.second;
      if (key == "adapter") r_.choice(v, "adapter", kAdapters, t.adapter);
      if (key == "capabilities") capabilities(v, where, t);
      if (key == "limits") {
        LimitOverrides given;
        limits(v, where, given);
        given.apply(t.limits);
        if (given.max_altitude_at) out_.type_max_altitude_at[name] = *given.max_altitude_at;
      }
      if (key == "tolerance") tolerance(v, where, t.tolerance);
      if (key == "sensors" && r_.whole_number(v, "sensors of " + where, sensor_count) &&
          (sensor_count < 0 || sensor_count > kMaxSensors)) {
        r_.error(v, "sensors of " + where + " must be from 0 to " + std::to_string(kMaxSensors) +
                        "; got " + describe(v));
        sensor_count = t.sensors;
      }
    }
  }
  set_sensors(t, static_cast<int>(sensor_count));
  max_sensors_ = std::max(max_sensors_, t.sensors);
  out_.types[name] = std::move(t);
}

void FleetParser::capabilities(const YAML::Node& node, const std::string& where, DroneType& type) {
  if (!node.IsSequence()) {
    r_.error(node, "capabilities of " + where + " must be a list of action names, e.g. "
                   "[Arm, Takeoff, Land]; got " + describe(node));
    return;
  }
  const std::vector<std::string> actions = standard_action_names();
  std::set<std::string> listed;
  for (const auto& item : node) {
    std::string name;
    if (!r_.text(item, "a capability of " + where, name)) continue;
    if (std::find(actions.begin(), actions.end(), name) != actions.end()) {
      if (!listed.insert(name).second)
        r_.diags.warning(r_.file, location_of(item.Mark()),
                         "capability '" + name + "' is listed twice in " + where + "; remove one");
    } else if (sensor_index(name, kMaxSensors) > 0) {
      r_.error(item, "'" + name + "' does not belong in capabilities; sensors come from "
                     "`sensors: N` in " + where);
    } else if (is_standard_property(name)) {
      r_.error(item, "'" + name + "' is a property, and every type has all properties; list only "
                     "actions in capabilities");
    } else {
      std::string near = closest_match(name, actions);
      r_.error(item, "unknown capability " + describe(item) + " in " + where +
                         (near.empty() ? "; the actions are " + one_of(actions)
                                       : "; did you mean '" + near + "'?"));
    }
  }
  // Keep the catalog's order so every listing of a type reads the same way.
  std::erase_if(type.actions, [&](const ActionSpec& a) { return !listed.count(a.name); });
}

void FleetParser::limits(const YAML::Node& node, const std::string& where, LimitOverrides& out) {
  if (!r_.map(node, "limits of " + where)) return;
  std::set<std::string> seen;
  for (const auto& kv : node) {
    std::string key = r_.field(kv.first, kLimitKeys, seen, "limits of " + where);
    if (key.empty()) continue;
    double value = 0;
    std::string what = key + " of " + where;
    if (!r_.number(kv.second, what, value)) continue;
    if (value <= 0) {
      r_.error(kv.second, what + " must be positive; got " + describe(kv.second) +
                              "; limits are magnitudes in m, m/s or m/s²");
      continue;
    }
    if (key == "max_speed") out.max_speed_mps = value;
    if (key == "max_climb") out.max_climb_mps = value;
    if (key == "max_descent") out.max_descent_mps = value;
    if (key == "max_accel") out.max_accel_mps2 = value;
    if (key == "max_altitude") {
      out.max_altitude_m = value;
      out.max_altitude_at = location_of(kv.second.Mark());
    }
  }
}

void FleetParser::drones(const YAML::Node& node) {
  if (!r_.map(node, "drones")) return;
  std::set<std::string> seen;
  for (const auto& kv : node) {
    if (saturated()) return;
    std::string name = r_.name(kv.first, seen, "drones");
    if (name.empty()) continue;
    out_.drone_locations[name] = location_of(kv.first.Mark());
    drone(name, kv.second);
  }
}

void FleetParser::drone(const std::string& name, const YAML::Node& node) {
  DroneSettings s;
  s.name = name;
  s.type = "";  // the mission names the type; settings_for fills it in
  DroneOverrides o;
  const std::string where = "drone '" + name + "'";
  std::set<std::string> seen;
  if (r_.map(node, where)) {
    for (const auto& kv : node) {
      std::string key = r_.field(kv.first, kDroneKeys, seen, where);
      const YAML::Node& v = kv.second;
      std::string what = key + " of " + where;
      if (key == "home") o.home = r_.vec3(v, what, s.home);
      if (key == "battery" && r_.number(v, what, s.battery_percent) &&
          (s.battery_percent < 0 || s.battery_percent > 100)) {
        r_.error(v, what + " must be a charge from 0 to 100 (%); got " + describe(v));
        s.battery_percent = 100;
      }
      if (key == "sensors") sensors(v, where, s, o);
      if (key == "limits") limits(v, where, o.limits);
      std::string failsafe;
      if (key == "failsafe" && r_.choice(v, "failsafe", kFailsafes, failsafe))
        s.failsafe = failsafe_from(failsafe);
      if (key == "adapter") o.adapter = r_.choice(v, "adapter", kAdapters, s.adapter);
      if (key == "connection" && r_.text(v, what, s.connection)) check_connection(v, what, s.connection);
      long long sysid = 0;
      if (key == "sysid" && r_.whole_number(v, what, sysid)) {
        if (sysid >= 1 && sysid <= 255) s.sysid = static_cast<int>(sysid);
        else r_.error(v, what + " must be a MAVLink system id from 1 to 255; got " + describe(v));
      }
      long long priority = 0;
      if (key == "priority" && r_.whole_number(v, what, priority)) {
        if (priority >= 1 && priority <= 1000000) s.priority = static_cast<int>(priority);
        else r_.error(v, what + " must be a whole number from 1 (goes first) to 1000000; got " + describe(v));
      }
      if (key == "timeouts") timeouts(v, where, s);
      if (key == "geofence") geofence(v, where, o.geofence);
      if (key == "signing") signing(v, where, s);
      if (key == "announce_as_gcs") flag(v, what, s.announce_as_gcs);
      if (key == "gust") gust(v, what, s.gust);
    }
  }
  out_.drones[name] = std::move(s);
  out_.overrides[name] = std::move(o);
}

void FleetParser::signing(const YAML::Node& node, const std::string& where, DroneSettings& settings) {
  const std::string what = "signing of " + where;
  if (!r_.map(node, what)) {
    if (!node.IsNull()) return;
    r_.error(node, what + " needs `key_file: PATH` (or `key: HEX`); make a key with `openssl rand -hex 32`");
    return;
  }
  std::set<std::string> seen;
  std::string key, file;
  // The key's value node, for the error's place. A copy, not a pointer: the map's iterator
  // yields each pair as a temporary that is gone after its round. Not assigned with `=`, which
  // would write into the document: a YAML::Node is a handle.
  std::optional<YAML::Node> value;
  for (const auto& kv : node) {
    std::string field = r_.field(kv.first, kSigningKeys, seen, what);
    if (field == "key" && r_.text(kv.second, "key of " + what, key)) value.emplace(kv.second);
    if (field == "key_file" && r_.text(kv.second, "key_file of " + what, file)) value.emplace(kv.second);
    if (field == "setup" && !kv.second.IsScalar())
      r_.error(kv.second, "setup of " + what + " must be true or false; got " + describe(kv.second));
    else if (field == "setup" && !YAML::convert<bool>::decode(kv.second, settings.signing_setup))
      r_.error(kv.second, "setup of " + what + " must be true or false; got " + describe(kv.second));
  }
  if (key.empty() == file.empty()) {
    r_.error(node, what + " needs exactly one of `key_file: PATH` and `key: HEX`");
    return;
  }
  if (!file.empty()) {
    // Relative to the fleet file, like every path a fleet file names.
    std::filesystem::path p(file);
    if (p.is_relative() && r_.file && !r_.file->path.empty()) p = std::filesystem::path(r_.file->path).parent_path() / p;
    if (std::string why = read_signing_key_file(p.string(), key); !why.empty()) return r_.error(value.value_or(node), why);
  } else if (std::string why = signing_key_problem(key); !why.empty()) {
    return r_.error(value.value_or(node), "key of " + what + ": " + why);
  }
  settings.signing_key = key;
}

void FleetParser::sensors(const YAML::Node& node, const std::string& where,
                          DroneSettings& settings, DroneOverrides& overrides) {
  if (!r_.map(node, "sensors of " + where)) return;
  std::set<std::string> seen;
  for (const auto& kv : node) {
    std::string name = r_.key(kv.first, seen, "sensors of " + where);
    if (name.empty()) continue;
    if (sensor_index(name, kMaxSensors) == 0) {
      r_.error(kv.first, "unknown sensor " + describe(kv.first) + " in " + where +
                             "; sensors are named Sensor1, Sensor2, ... up to the type's `sensors:`");
      continue;
    }
    if (sensor_index(name, max_sensors_) == 0) {
      r_.error(kv.first, "'" + name + "' of " + where + " is beyond every type's sensor count (at most " +
                             std::to_string(max_sensors_) + "); raise `sensors:` in the drone's type");
      continue;
    }
    overrides.sensor_locations[name] = location_of(kv.first.Mark());
    std::optional<SensorRange> range;
    sensor(kv.second, name + " of " + where, settings.sensors[name], range);
    if (range) overrides.sensor_ranges[name] = *range;
  }
}

void FleetParser::sensor(const YAML::Node& node, const std::string& what, SensorModel& out,
                         std::optional<SensorRange>& range_out) {
  if (!node.IsMap()) {
    if (!r_.number(node, what, out.base))
      r_.diags.note(r_.file, location_of(node.Mark()),
                    "write a sensor as a number, or as {value: V, gradient: [gx, gy, gz]}");
    return;
  }
  std::set<std::string> seen;
  for (const auto& kv : node) {
    std::string key = r_.field(kv.first, kSensorKeys, seen, what);
    if (key == "value") r_.number(kv.second, "value of " + what, out.base);
    if (key == "gradient") r_.vec3(kv.second, "gradient of " + what, out.gradient);
    if (key == "range") range(kv.second, "range of " + what, range_out);
  }
}

void FleetParser::range(const YAML::Node& node, const std::string& what, std::optional<SensorRange>& out) {
  if (!node.IsSequence() || node.size() != 2) {
    r_.error(node, what + " must be a list of two numbers [low, high], the least and the most the sensor "
                          "can read; got " + (node.IsSequence() ? "a list of " + std::to_string(node.size())
                                                                 : describe(node)));
    return;
  }
  SensorRange r;
  bool ok = r_.number(node[0], "low end of " + what, r.low);
  ok = r_.number(node[1], "high end of " + what, r.high) && ok;
  if (!ok) return;
  if (r.low > r.high) {
    r_.error(node, what + " must be [low, high] with low <= high; got [" + describe(node[0]) + ", " +
                       describe(node[1]) + "]; swap them");
    return;
  }
  out = r;
}

// The whole URL is checked here (the parser the mavlink adapter connects with), so that
// `eamos check` reports a wrong scheme, port, device or serial rate at its line.
void FleetParser::check_connection(const YAML::Node& node, const std::string& what, const std::string& url) {
  EndpointResult parsed = parse_link_url(url);
  if (!parsed.endpoint) r_.error(node, what + ": " + parsed.error);
}

void FleetParser::safety(const YAML::Node& node) {
  if (!r_.map(node, "safety")) return;
  Safety& s = out_.safety;
  std::set<std::string> seen;
  for (const auto& kv : node) {
    std::string key = r_.field(kv.first, kSafetyKeys, seen, "safety");
    const YAML::Node& v = kv.second;
    double value = 0;
    if (key == "min_separation") separation(v, s.min_separation);
    if (key == "battery_reserve" && r_.number(v, "battery_reserve of safety", value)) {
      if (value < 0 || value > 100)
        r_.error(v, "battery_reserve of safety must be a charge from 0 to 100 (%); got " + describe(v));
      else
        s.battery_reserve_percent = value;
    }
    if (key == "max_speed" && positive(v, "max_speed of safety", value)) s.max_speed_mps = value;
    if (key == "home_tolerance" && positive(v, "home_tolerance of safety", value)) s.home_tolerance_m = value;
    if (key == "max_climb" && positive(v, "max_climb of safety", value)) s.max_climb_mps = value;
    if (key == "max_descent" && positive(v, "max_descent of safety", value)) s.max_descent_mps = value;
    if (key == "geofence") geofence(v, "safety", s.geofence);
  }
}

bool FleetParser::flag(const YAML::Node& node, const std::string& what, bool& out) {
  if (node.IsScalar() && YAML::convert<bool>::decode(node, out)) return true;
  r_.error(node, what + " must be true or false; got " + describe(node));
  return false;
}

void FleetParser::gust(const YAML::Node& node, const std::string& what, std::optional<Gust>& out) {
  if (!node.IsMap()) {
    r_.error(node, what + " must be a map {at: S, for: S, velocity: [vx, vy, vz]}; got " + describe(node));
    return;
  }
  Gust g;
  bool ok = true;
  std::set<std::string> seen;
  for (const auto& kv : node) {
    std::string key = r_.field(kv.first, kGustKeys, seen, what);
    if (key == "at") {
      ok &= r_.number(kv.second, "at of " + what, g.at_s);
      if (g.at_s < 0) {
        r_.error(kv.second, "at of " + what + " must be a mission time (s) not below 0; got " + describe(kv.second));
        ok = false;
      }
    }
    if (key == "for") ok &= positive(kv.second, "for of " + what, g.for_s);
    if (key == "velocity") ok &= r_.vec3(kv.second, "velocity of " + what, g.velocity);
  }
  if (!seen.count("for") || !seen.count("velocity")) {
    r_.error(node, what + " needs `for` (s) and `velocity` ([vx, vy, vz] m/s); e.g. {at: 5, for: 2, velocity: [10, 0, 0]}");
    ok = false;
  }
  if (ok) out = g;
}

bool FleetParser::positive(const YAML::Node& node, const std::string& what, double& out) {
  double value = 0;
  if (!r_.number(node, what, value)) return false;
  if (value <= 0) {
    r_.error(node, what + " must be positive; got " + describe(node));
    return false;
  }
  out = value;
  return true;
}

void FleetParser::separation(const YAML::Node& node, Separation& out) {
  positive_fields(node, "min_separation of safety", "{horizontal: M, vertical: M}", kSeparationKeys,
                  {&out.horizontal_m, &out.vertical_m});
}

void FleetParser::tolerance(const YAML::Node& node, const std::string& where, GoalTolerance& out) {
  positive_fields(node, "tolerance of " + where, "{horizontal: M, vertical: M, speed: M/S}", kToleranceKeys,
                  {&out.horizontal_m, &out.vertical_m, &out.settled_mps});
}

void FleetParser::positive_fields(const YAML::Node& node, const std::string& what, const std::string& shape,
                                  const std::vector<std::string>& keys, const std::vector<double*>& fields) {
  if (!node.IsMap()) {
    r_.error(node, what + " must be a map " + shape + "; got " + describe(node));
    return;
  }
  std::set<std::string> seen;
  for (const auto& kv : node) {
    const std::string key = r_.field(kv.first, keys, seen, what);
    const auto k = std::find(keys.begin(), keys.end(), key);
    double value = 0;
    if (k != keys.end() && positive(kv.second, key + " of " + what, value)) *fields[k - keys.begin()] = value;
  }
}

void FleetParser::geofence(const YAML::Node& node, const std::string& where, std::optional<Geofence>& out) {
  const std::string what = "geofence of " + where;
  if (!node.IsMap()) {
    r_.error(node, what + " must be a map {polygon: [[x, y], ...], min_altitude: M, max_altitude: M}; got " +
                       describe(node));
    return;
  }
  Geofence g;
  std::set<std::string> seen;
  std::optional<YAML::Node> max_node;
  for (const auto& kv : node) {
    std::string key = r_.field(kv.first, kGeofenceKeys, seen, what);
    double value = 0;
    if (key == "polygon") polygon(kv.second, "polygon of " + what, g);
    if (key == "upload") flag(kv.second, "upload of " + what, g.upload);
    if (key == "min_altitude" && r_.number(kv.second, "min_altitude of " + what, value)) g.min_altitude_m = value;
    if (key == "max_altitude" && r_.number(kv.second, "max_altitude of " + what, value)) {
      g.max_altitude_m = value;
      g.max_altitude_at = location_of(kv.second.Mark());
      max_node = kv.second;
    }
  }
  if (g.upload && g.polygon.empty()) {
    r_.error(node, "upload of " + what + " needs a polygon: an autopilot's fence is a polygon (with an "
                   "altitude ceiling); add `polygon: [[x, y], ...]` or drop `upload`");
    return;
  }
  if (g.min_altitude_m && g.max_altitude_m && *g.min_altitude_m >= *g.max_altitude_m) {
    r_.error(*max_node, "max_altitude of " + what + " must be above its min_altitude (" +
                            describe(*max_node) + " is not above " + diag::number_text(*g.min_altitude_m) +
                            "); swap them or widen the band");
    return;
  }
  out = std::move(g);
}

void FleetParser::polygon(const YAML::Node& node, const std::string& what, Geofence& out) {
  if (!node.IsSequence() || node.size() < 3) {
    r_.error(node, what + " must be a list of at least three corners [[x, y], [x, y], [x, y]] in metres of "
                          "the mission frame; got " +
                       (node.IsSequence() ? "a list of " + std::to_string(node.size()) : describe(node)));
    return;
  }
  std::vector<std::pair<double, double>> corners;
  bool ok = true;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node& c = node[i];
    std::string corner = "corner " + std::to_string(i + 1) + " of " + what;
    if (!c.IsSequence() || c.size() != 2) {
      r_.error(c, corner + " must be a list of two numbers [x, y]; got " +
                      (c.IsSequence() ? "a list of " + std::to_string(c.size()) : describe(c)));
      ok = false;
      continue;
    }
    double x = 0, y = 0;
    bool good = r_.number(c[0], corner + " [x]", x);
    good = r_.number(c[1], corner + " [y]", y) && good;
    ok = ok && good;
    corners.emplace_back(x, y);
  }
  if (!ok) return;
  double twice_area = 0;
  for (std::size_t i = 0, j = corners.size() - 1; i < corners.size(); j = i++)
    twice_area += corners[j].first * corners[i].second - corners[i].first * corners[j].second;
  if (std::abs(twice_area) < 1e-9) {
    r_.error(node, what + " encloses no area (its corners lie on one line); give the corners of the area "
                          "the drones may fly in");
    return;
  }
  out.polygon = std::move(corners);
}

void FleetParser::timeouts(const YAML::Node& node, const std::string& where, DroneSettings& settings) {
  const std::string what = "timeouts of " + where;
  if (!r_.map(node, what)) return;
  std::set<std::string> seen;
  for (const auto& kv : node) {
    std::string action = r_.key(kv.first, seen, what);
    if (action.empty()) continue;
    std::vector<std::string> names = standard_action_names();
    if (std::find(names.begin(), names.end(), action) == names.end()) {
      std::string near = closest_match(action, names);
      r_.error(kv.first, "unknown action " + describe(kv.first) + " in " + what +
                             (near.empty() ? "; the actions are " + one_of(names)
                                           : "; did you mean '" + near + "'?"));
      continue;
    }
    double seconds = 0;
    if (!r_.number(kv.second, action + " in " + what, seconds)) continue;
    if (seconds <= 0) {
      r_.error(kv.second, action + " in " + what + " must be a positive number of seconds; got " +
                              describe(kv.second));
      continue;
    }
    settings.timeouts_s[action] = seconds;
  }
}

// yaml-cpp names the grammar rule, not the mistake; the commonest one, a tab in the
// indentation, gives "illegal map value", so say what to do about it.
std::string syntax_hint(const SourceFile& file, SourceLocation loc) {
  for (int line = std::max(1, loc.line - 1); line <= loc.line; ++line) {
    std::string_view text = file.line(line);
    std::size_t indent = text.find_first_not_of(" \t");
    if (text.substr(0, indent).find('\t') != std::string_view::npos)
      return "YAML does not allow tabs in indentation; indent with spaces";
  }
  return "check the indentation, colons and brackets here";
}

}  // namespace

bool parse_fleet(std::shared_ptr<SourceFile> source, Fleet& out, Diagnostics& diags) {
  out = Fleet{};
  if (!source) source = std::make_shared<SourceFile>();
  out.path = source->path;
  out.source = source;
  const SourceFile* file = source.get();
  std::size_t errors_before = diags.error_count();
  // yaml-cpp reports by exception; here they become diagnostics, so nothing escapes.
  try {
    YAML::Node root;
    if (load_one_document(source->text, root, file, diags)) FleetParser(file, out, diags).parse(root);
  } catch (const YAML::ParserException& e) {
    SourceLocation loc = location_of(e.mark);
    diags.error(file, loc, "YAML syntax error: " + e.msg + "; " + syntax_hint(*file, loc));
  } catch (const YAML::Exception& e) {
    diags.error(file, location_of(e.mark), "cannot read the fleet file: " + e.msg);
  } catch (const std::exception& e) {
    diags.error(file, {}, std::string("cannot read the fleet file: ") + e.what());
  }
  return diags.error_count() == errors_before;
}

}  // namespace eamos::fleet
