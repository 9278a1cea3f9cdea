#pragma once
// The platform catalog: which capabilities each drone type has, and which adapter flies
// it. The compiler checks every action call and property read against it, the way a
// BehaviorTree.CPP factory rejects unknown node names at load time, not in flight.
#include <string>
#include <string_view>
#include <vector>

namespace eamos::fleet {

enum class ValueType { number, boolean };

/// How an action uses the vehicle: at most one motion action runs per drone at a time
/// (a new one preempts the old), payload actions run beside motion, system actions
/// (arm/disarm) change the vehicle's state without moving it.
enum class ActionClass { motion, payload, system };

/// "motion", "payload" or "system", as mission files write it.
const char* action_class_name(ActionClass k);

struct ActionSpec {
  std::string name;          ///< e.g. "FlyTo"
  std::vector<int> arities;  ///< accepted argument counts; every argument is a number
  ActionClass action_class = ActionClass::motion;
  std::string params;        ///< human text for help and errors, e.g. "x_m, y_m, z_m"
};

struct PropertySpec {
  std::string name;  ///< e.g. "X"
  ValueType type = ValueType::number;
  std::string unit;  ///< "m", "%", "" for booleans
};

/// Kinematic limits of a platform; the simulator flies within them and action timeouts
/// are derived from them.
struct Limits {
  double max_speed_mps = 10.0;     ///< horizontal
  double max_climb_mps = 3.0;      ///< vertical up
  double max_descent_mps = 2.0;    ///< vertical down
  double max_accel_mps2 = 4.0;
  double max_altitude_m = 120.0;
};

/// When a motion's goal counts as reached on a real vehicle (fleet file `tolerance:` per
/// type, docs/fleet.md): within `horizontal_m` in x/y, `vertical_m` in z and no faster than
/// `settled_mps` (stopped there, not passing by). A vehicle never stops exactly on its
/// setpoint; the simulator does, so it meets any tolerance.
struct GoalTolerance {
  double horizontal_m = 0.5;
  double vertical_m = 0.3;
  double settled_mps = 0.3;
};

struct DroneType {
  std::string name;              ///< as written after `var Drone NAME`
  std::string adapter = "sim";   ///< Adapter Space key: "sim" (built in) or "mavlink"
  std::vector<ActionSpec> actions;
  std::vector<PropertySpec> properties;
  int sensors = 8;               ///< Sensor1 … SensorN exist as properties and actions;
                                 ///< change it with set_sensors() so the specs follow
  Limits limits;
  GoalTolerance tolerance;
  bool generic = true;           ///< true: the built-in multirotor (not described by a file)

  const ActionSpec* find_action(std::string_view name) const;
  const PropertySpec* find_property(std::string_view name) const;
  /// Names of all actions and properties, for "did you mean" suggestions.
  std::vector<std::string> capability_names() const;
};

/// The standard capabilities of the uniform drone API; names and units are fixed.
const std::vector<ActionSpec>& standard_actions();
const std::vector<PropertySpec>& standard_properties();
/// A fleet file may give a type at most this many sensors; more is a typo, not a drone.
constexpr int kMaxSensors = 64;
/// Sets `type.sensors` and makes Sensor1 … SensorN its (payload, no-argument) actions and
/// (number) properties, replacing any SensorK specs it had.
void set_sensors(DroneType& type, int sensors);
/// The built-in generic multirotor, named `type_name`: every standard capability, 8 sensors.
DroneType generic_multirotor(const std::string& type_name);
/// "SensorK" with 1 <= K <= sensors: returns K, else 0.
int sensor_index(const std::string& name, int sensors);

/// One argument of a standard action in words, with its unit: what editors show on hover
/// (eamos lsp) and what docs/language.md §5 and docs/fleet.md state.
struct ParamDoc {
  std::string name;     ///< as the signature writes it, e.g. "x"
  std::string unit;     ///< "metres", "seconds", ...; "" for a plain number
  std::string meaning;  ///< e.g. "position east of the mission frame's origin"
};

/// A standard capability in words. For an action, `params` lists its arguments in order
/// (an optional last one when the action accepts one fewer); for a property, `unit` is the
/// unit of the value it reads.
struct CapabilityDoc {
  std::string name;     ///< "FlyTo"; "SensorK" stands for every Sensor1 ... SensorN
  std::string summary;  ///< what the action does or the property reads
  std::vector<ParamDoc> params;
  std::string unit;     ///< a property's unit in words; "" for an action or a boolean
};

/// The standard capabilities in words, one entry per action and property name (SensorK once).
const std::vector<CapabilityDoc>& capability_docs();
/// The entry for an action or property name ("Sensor3" finds "SensorK"); null when none.
const CapabilityDoc* capability_doc(const std::string& name);

}  // namespace eamos::fleet
