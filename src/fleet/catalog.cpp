#include "fleet/catalog.h"

#include <limits>

namespace eamos::fleet {

const char* action_class_name(ActionClass k) {
  switch (k) {
    case ActionClass::motion: return "motion";
    case ActionClass::payload: return "payload";
    case ActionClass::system: return "system";
  }
  return "";
}

namespace {
bool is_sensor_name(const std::string& name) {
  return sensor_index(name, std::numeric_limits<int>::max()) > 0;
}
}  // namespace

const std::vector<ActionSpec>& standard_actions() {
  static const std::vector<ActionSpec> actions = {
      {"Arm", {0}, ActionClass::system, ""},
      {"Disarm", {0}, ActionClass::system, ""},
      {"Takeoff", {1}, ActionClass::motion, "alt_m"},
      {"Land", {0}, ActionClass::motion, ""},
      {"FlyTo", {3}, ActionClass::motion, "x_m, y_m, z_m"},
      {"FlyBy", {3}, ActionClass::motion, "dx_m, dy_m, dz_m"},
      {"FlyByX", {1}, ActionClass::motion, "dx_m"},
      {"FlyByY", {1}, ActionClass::motion, "dy_m"},
      {"FlyByZ", {1}, ActionClass::motion, "dz_m"},
      // Without an argument Hover holds until a later motion action preempts it.
      {"Hover", {0, 1}, ActionClass::motion, "[seconds]"},
      {"Orbit", {0, 1}, ActionClass::motion, "[radius_m]"},
      {"ReturnHome", {0}, ActionClass::motion, ""},
      {"TakePicture", {0}, ActionClass::payload, ""},
  };
  return actions;
}

const std::vector<PropertySpec>& standard_properties() {
  static const std::vector<PropertySpec> properties = {
      {"X", ValueType::number, "m"},       {"Y", ValueType::number, "m"},
      {"Z", ValueType::number, "m"},       {"Battery", ValueType::number, "%"},
      {"Armed", ValueType::boolean, ""},   {"Landed", ValueType::boolean, ""},
  };
  return properties;
}

void set_sensors(DroneType& type, int sensors) {
  // Drop the old SensorK entries first so a type can be resized after construction.
  std::erase_if(type.actions, [](const ActionSpec& a) { return is_sensor_name(a.name); });
  std::erase_if(type.properties, [](const PropertySpec& p) { return is_sensor_name(p.name); });
  type.sensors = sensors;
  for (int k = 1; k <= sensors; ++k) {
    std::string name = "Sensor" + std::to_string(k);
    type.actions.push_back({name, {0}, ActionClass::payload, ""});
    type.properties.push_back({name, ValueType::number, ""});
  }
}

DroneType generic_multirotor(const std::string& type_name) {
  DroneType type;
  type.name = type_name;
  type.adapter = "sim";
  type.actions = standard_actions();
  type.properties = standard_properties();
  type.generic = true;
  set_sensors(type, 8);
  return type;
}

const ActionSpec* DroneType::find_action(std::string_view action) const {
  for (const auto& a : actions)
    if (a.name == action) return &a;
  return nullptr;
}

const PropertySpec* DroneType::find_property(std::string_view property) const {
  for (const auto& p : properties)
    if (p.name == property) return &p;
  return nullptr;
}

std::vector<std::string> DroneType::capability_names() const {
  std::vector<std::string> names;
  for (const auto& a : actions) names.push_back(a.name);
  // SensorK is both an action and a property; list it once.
  for (const auto& p : properties)
    if (!find_action(p.name)) names.push_back(p.name);
  return names;
}

// Units in words, one table: the catalog above fixes names and arities, this says what the
// numbers mean. The frame is the mission's local one: x east, y north, z up, metres, z = 0
// at home ground level (docs/language.md §5).
const std::vector<CapabilityDoc>& capability_docs() {
  static const std::vector<CapabilityDoc> docs = {
      {"Arm", "arm the motors", {}, ""},
      {"Disarm", "disarm the motors", {}, ""},
      {"Takeoff", "take off and climb to an altitude", {{"alt", "metres", "altitude above home ground level"}}, ""},
      {"Land", "land where the drone is", {}, ""},
      {"FlyTo", "fly to a position in the mission frame",
       {{"x", "metres", "east of the frame's origin"},
        {"y", "metres", "north of the frame's origin"},
        {"z", "metres", "up from home ground level"}}, ""},
      {"FlyBy", "fly by an offset from where the drone is",
       {{"dx", "metres", "east"}, {"dy", "metres", "north"}, {"dz", "metres", "up"}}, ""},
      {"FlyByX", "fly by an offset east (negative: west)", {{"dx", "metres", "east"}}, ""},
      {"FlyByY", "fly by an offset north (negative: south)", {{"dy", "metres", "north"}}, ""},
      {"FlyByZ", "fly by an offset up (negative: down)", {{"dz", "metres", "up"}}, ""},
      {"Hover", "hold position; without an argument until a later motion action preempts it",
       {{"s", "seconds", "how long to hold (optional)"}}, ""},
      {"Orbit", "circle around where the drone is", {{"r", "metres", "radius of the circle (optional)"}}, ""},
      {"ReturnHome", "fly back to home", {}, ""},
      {"TakePicture", "take a picture", {}, ""},
      {"SensorK", "as a statement, take a reading with sensor K; in an expression, its last reading, "
                  "in the sensor's own unit (K = 1 ... the type's sensor count)", {}, ""},
      {"X", "position east of the mission frame's origin", {}, "metres"},
      {"Y", "position north of the mission frame's origin", {}, "metres"},
      {"Z", "height above home ground level", {}, "metres"},
      {"Battery", "charge left", {}, "percent"},
      {"Armed", "true while the motors are armed", {}, ""},
      {"Landed", "true while the drone is on the ground", {}, ""},
  };
  return docs;
}

const CapabilityDoc* capability_doc(const std::string& name) {
  const std::string key = is_sensor_name(name) ? "SensorK" : name;
  for (const auto& d : capability_docs())
    if (d.name == key) return &d;
  return nullptr;
}

int sensor_index(const std::string& name, int sensors) {
  const std::string prefix = "Sensor";
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) return 0;
  std::string digits = name.substr(prefix.size());
  // "Sensor01" is not a name the catalog generates, and more digits would overflow.
  if (digits[0] == '0' || digits.size() > 9) return 0;
  int k = 0;
  for (char c : digits) {
    if (c < '0' || c > '9') return 0;
    k = k * 10 + (c - '0');
  }
  return k <= sensors ? k : 0;
}

}  // namespace eamos::fleet
