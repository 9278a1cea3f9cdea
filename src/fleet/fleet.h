#pragma once
// The fleet file (YAML): drone types with their capability sets, and per-drone settings
// (home, sensors, limits, failsafe, adapter and connection). Without a file every type
// is the generic multirotor and drone i starts at (0, 5·i, 0) with all sensors at 0.
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "diag/diagnostics.h"
#include "fleet/catalog.h"

namespace eamos::fleet {

struct Vec3 {
  double x = 0, y = 0, z = 0;
};

/// A simulated sensor: value = base + gradient · position (a constant when gradient = 0).
struct SensorModel {
  double base = 0.0;
  Vec3 gradient;
};

/// What an airborne drone does when the mission fails.
enum class Failsafe { land, return_home, hover };
const char* failsafe_name(Failsafe f);

/// How far (m, horizontally) the vehicles may stand from where their declared homes put them,
/// relative to each other, before the mission refuses to arm (`safety: home_tolerance:`).
inline constexpr double kDefaultHomeToleranceM = 3.0;

/// Where drones may fly (docs/fleet.md, `geofence:`): inside a polygon of the mission frame's
/// x/y plane (none: anywhere) and between two altitudes (each optional). `eamos verify`
/// checks the flown tracks and every motion target against it; in flight every adapter's
/// drone refuses a target outside it and fails over when the drone leaves it (mid/site_limits.h).
struct Geofence {
  std::vector<std::pair<double, double>> polygon;  ///< (x east, y north), m; empty = no polygon
  std::optional<double> min_altitude_m;
  std::optional<double> max_altitude_m;
  /// `upload: true`: the mavlink adapter also gives the fence to the autopilot (its own
  /// polygon fence, FENCE_* / GF_*), so the vehicle holds it without the companion computer.
  bool upload = false;
  std::optional<SourceLocation> max_altitude_at;  ///< where the fleet file sets max_altitude
  /// True when (x, y, z) lies inside (a point on the boundary is inside).
  bool contains(double x, double y, double z) const;
  bool contains_xy(double x, double y) const;
};

/// The site's rules one drone keeps in flight (`safety:` in the fleet file, and the drone's
/// own `geofence:`): they travel in its mission file, so the DEX that flies
/// it needs nothing else. Empty members: no such rule.
struct SiteLimits {
  std::optional<Geofence> geofence;
  std::optional<double> max_speed_mps;    ///< horizontal
  std::optional<double> max_climb_mps;
  std::optional<double> max_descent_mps;
  bool empty() const {
    return !geofence && !max_speed_mps && !max_climb_mps && !max_descent_mps;
  }
};

/// The simulator's deterministic push (`gust:` of a drone): from mission time `at_s` for
/// `for_s` seconds the air moves the drone by `velocity` on top of whatever it flies, as a
/// gust stronger than its motors would. For testing what happens when a drone is pushed
/// out of its fence; other adapters ignore it.
struct Gust {
  double at_s = 0.0;
  double for_s = 0.0;
  Vec3 velocity;  ///< m/s, mission frame
};

struct DroneSettings {
  std::string name;
  std::string type;
  Vec3 home;                                 ///< local frame: x east, y north, z up (m)
  std::map<std::string, SensorModel> sensors;  ///< "Sensor1" → model; missing = 0
  Limits limits;                             ///< the type's limits, overridden per drone
  GoalTolerance tolerance;                   ///< the type's
  Failsafe failsafe = Failsafe::land;
  std::string adapter = "sim";
  std::string connection;                    ///< adapter URL, e.g. udp://:14540; "" for sim
  int sysid = 0;                             ///< MAVLink system id; 0 = not set
  double battery_percent = 100.0;            ///< charge at mission start
  /// Who gives way when two drones would come too close (docs/fleet.md `priority:`): the
  /// lower number goes first, ties to the drone declared first; 0 = not set, which ranks as
  /// the drone's place in the declaration order (1, 2, …).
  int priority = 0;
  std::map<std::string, double> timeouts_s;  ///< per action name; overrides derived ones
  /// MAVLink 2 signing (docs/fleet.md `signing:`): the link's secret key as 64 hex digits;
  /// "" = frames unsigned. A secret: only the drone's own deployment folder holds it.
  std::string signing_key;
  bool signing_setup = false;  ///< send the key to the vehicle (SETUP_SIGNING) at connect
  /// MAVLink: also send a ground station's HEARTBEAT (MAV_TYPE_GCS), so that a PX4 that
  /// gives STATUSTEXT only to a link with a GCS tells us why it refused (docs/fleet.md:
  /// it also hides the loss of the real ground station from PX4's link-loss failsafe).
  bool announce_as_gcs = false;
  SiteLimits site;             ///< the site's rules this drone keeps in flight
  std::optional<Gust> gust;    ///< simulator only
  /// The fleet's `safety: home_tolerance` (mid/home_check.h).
  double home_tolerance_m = kDefaultHomeToleranceM;
};

/// "" when `hex` is a usable signing key (64 hex digits, not all zero), else what is wrong.
std::string signing_key_problem(const std::string& hex);
/// Reads a signing key file (64 hex digits, a final newline allowed) into `hex`; "" on
/// success, else what is wrong and how to fix it. A file that its group or others may read
/// or write is refused: the key lets whoever holds it fly the vehicle.
std::string read_signing_key_file(const std::string& path, std::string& hex);

/// Two airborne drones are too close when they are nearer than `horizontal_m` horizontally
/// and nearer than `vertical_m` vertically at the same time.
struct Separation {
  double horizontal_m = 2.0;
  double vertical_m = 1.0;
};

/// The fleet's operating rules (`safety:`): checked by `eamos verify` before a flight, and
/// (geofence and speeds, through each drone's SiteLimits) kept by every drone in flight.
/// The speed limits here are the operator's, not the vehicle's: a drone able to fly 10 m/s
/// may be allowed 5 m/s over a site.
struct Safety {
  Separation min_separation;
  double battery_reserve_percent = 20.0;  ///< land (or failsafe) with at least this much
  std::optional<double> max_speed_mps;     ///< horizontal
  std::optional<double> max_climb_mps;
  std::optional<double> max_descent_mps;
  std::optional<Geofence> geofence;        ///< every drone's, unless a drone gives its own
  /// Vehicles that report a global position must stand as their homes say within this (m).
  double home_tolerance_m = kDefaultHomeToleranceM;
};

/// The values a sensor may read in flight (`range: [low, high]`): what `eamos verify`
/// explores a condition on that sensor over, both ways where the range allows.
struct SensorRange {
  double low = 0.0;
  double high = 0.0;
};

/// Limits a fleet file sets; the unset ones keep the value they override (the defaults for
/// a type, the type's for a drone).
struct LimitOverrides {
  std::optional<double> max_speed_mps;
  std::optional<double> max_climb_mps;
  std::optional<double> max_descent_mps;
  std::optional<double> max_accel_mps2;
  std::optional<double> max_altitude_m;
  std::optional<SourceLocation> max_altitude_at;  ///< where the fleet file sets max_altitude

  void apply(Limits& limits) const;
};

/// The settings of a drone entry that fall back to something only known once the mission
/// names the drone's type and position: settings_for uses the entry's value only when set.
struct DroneOverrides {
  bool home = false;     ///< false: (0, 5·index, 0)
  bool adapter = false;  ///< false: the type's adapter
  LimitOverrides limits;  ///< unset: the type's limits
  std::map<std::string, SourceLocation> sensor_locations;  ///< where each SensorK is set
  std::map<std::string, SensorRange> sensor_ranges;        ///< SensorK → declared range
  std::optional<Geofence> geofence;                        ///< replaces the fleet's
};

struct Fleet {
  std::string path;                          ///< "" when no file was given
  std::map<std::string, DroneType> types;    ///< types described by the file
  std::map<std::string, DroneSettings> drones;  ///< drones described by the file, as written
                                                ///< (type "": the mission names it)
  std::map<std::string, DroneOverrides> overrides;  ///< per described drone: what it sets
  std::map<std::string, SourceLocation> drone_locations;  ///< where each drone is described
  std::shared_ptr<SourceFile> source;        ///< keeps the file text for diagnostics
  Safety safety;                             ///< operating rules for `eamos verify`
  /// Where a type's `limits:` set max_altitude, per type name (a note for diagnostics).
  std::map<std::string, SourceLocation> type_max_altitude_at;

  /// The geofence `drone` must stay in: its own, else the fleet's; null when neither is set.
  const Geofence* geofence_for(const std::string& drone) const;
  /// The declared range of `sensor` ("Sensor1") of `drone`; null when none is declared.
  const SensorRange* sensor_range(const std::string& drone, const std::string& sensor) const;

  /// The type for a name in the mission; an undescribed name is the generic multirotor.
  DroneType type_for(const std::string& type_name) const;
  /// Settings of the `index`-th declared drone (declaration order, from 0), with defaults
  /// for everything the file does not say.
  DroneSettings settings_for(const std::string& drone, const std::string& type_name,
                             int index) const;
  /// Reports sensors the file gives `drone` that its mission type `type` lacks; only the
  /// mission knows the type, so the checker calls this once per declared drone.
  void check_drone(const std::string& drone, const DroneType& type, Diagnostics& diags) const;
};

/// Loads and validates a fleet file; problems go to `diags` as file:line:col errors.
/// Returns false when the file could not be used.
bool load_fleet(const std::string& path, Fleet& out, Diagnostics& diags);
/// The same from text already in memory (tests, fuzzing).
bool parse_fleet(std::shared_ptr<SourceFile> source, Fleet& out, Diagnostics& diags);

}  // namespace eamos::fleet
