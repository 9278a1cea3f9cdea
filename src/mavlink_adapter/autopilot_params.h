#pragma once
// The autopilot's own speed limits, read from its parameters at connect time. A fleet file
// may say a drone descends at 2 m/s, but ArduCopter lands at LAND_SPEED (0.5 m/s) whatever
// the mission thinks: an action's deadline derived from the fleet's number would expire
// before a landing that is going perfectly well. So every deadline is derived from the slower
// of the fleet's limit and the autopilot's, and a fleet limit above the autopilot's is
// reported at start (the mission will be slower than the fleet file promises).
#include <map>
#include <string>
#include <vector>

#include "fleet/catalog.h"
#include "mavlink_adapter/autopilot.h"

namespace eamos::mavlink_adapter {

/// Which limit a parameter bounds.
/// takeoff_delay: seconds a takeoff spends before and beside its climb (motor spool-up,
/// the throttle or speed ramp); those of one autopilot add up.
/// accel: the horizontal acceleration the autopilot's position controller allows (m/s²); an
/// orbit's centripetal acceleration must stay below it or the vehicle swings wide.
/// return_home: how the autopilot's own return-to-launch flies (ReturnProfile), by name.
/// orbit_radius: the largest orbit the autopilot flies (PX4 MC_ORBIT_RAD_MAX, m).
enum class LimitKind { speed, climb, descent, land, takeoff_delay, accel, return_home, orbit_radius };

/// One parameter that bounds a limit: its name and the factor to m/s (ArduPilot: cm/s), to
/// m/s² for an acceleration, or to seconds for a takeoff delay.
struct LimitParam {
  const char* name;
  LimitKind kind;
  double to_mps;
};

/// The parameters read from `a`; several of one kind: the slowest counts.
std::vector<LimitParam> limit_params(const Autopilot& a);

/// How the autopilot's return-to-launch flies, which ReturnHome hands to it: it climbs to
/// its return altitude first, flies home, waits, then lands. A deadline for the straight way
/// home and down would expire on both autopilots: ArduCopter climbs to RTL_ALT 15 m
/// and loiters RTL_LOIT_TIME 5 s, PX4 climbs to RTL_RETURN_ALT 60 m.
struct ReturnProfile {
  /// ArduPilot RTL_ALT, PX4 RTL_RETURN_ALT: it climbs to at least this height above home
  /// (0: returns at its altitude). The autopilots' cones (RTL_CONE_SLOPE, RTL_CONE_ANG) only
  /// lower it near home, so it is an upper bound.
  double altitude_m = 0.0;
  double min_climb_m = 0.0;  ///< ArduPilot RTL_CLIMB_MIN: it climbs at least this much
  double speed_mps = 0.0;    ///< ArduPilot RTL_SPEED (0: the waypoint speed)
  double wait_s = 0.0;       ///< ArduPilot RTL_LOIT_TIME, PX4 RTL_LAND_DELAY: hovering over home
  bool lands = true;         ///< false: ArduPilot RTL_ALT_FINAL > 0 or PX4 RTL_LAND_DELAY < 0
};

/// The limits deadlines are derived from.
struct FlightLimits {
  fleet::Limits motion;      ///< speed, climb, descent of flying actions (FlyTo, Takeoff, …);
                             ///< max_accel_mps2 bounds the orbit's speed
  double land_mps = 0.0;     ///< descent of Land and ReturnHome (the autopilot's landing speed)
  /// Seconds a Takeoff takes beyond its climb at `motion.max_climb_mps`: measured on PX4 SIH,
  /// a 4 m takeoff spends 1 s spooling up (COM_SPOOLUP_TIME) and 3 s ramping its climb rate
  /// up (MPC_TKO_RAMP_T) before it climbs at all, so a deadline from the climb alone expires.
  double takeoff_delay_s = 0.0;
  ReturnProfile rtl;         ///< how ReturnHome flies on this autopilot
  double orbit_radius_max_m = 0.0;  ///< the largest DO_ORBIT radius it takes; 0 unknown
  std::vector<std::string> warnings;  ///< one line each: a fleet limit above the autopilot's,
                                      ///< or a parameter the autopilot did not tell
  std::string summary;       ///< "WPNAV_SPEED 10 m/s, …": what the autopilot said, for the log
};

/// The slower of the fleet's `fleet` and the autopilot's `values` (parameter name -> value in
/// the autopilot's unit; a missing, non-finite or non-positive value is unknown and leaves
/// the fleet's limit).
FlightLimits combine_limits(const Autopilot& a, const fleet::Limits& fleet,
                            const std::map<std::string, float>& values);

/// Seconds a ReturnHome takes from `height_m` above home and `distance_m` (horizontal) from
/// it at `l`: the climb to the return altitude at the climb speed, the way home at the
/// slower of the speed and the return speed, the wait, and the whole descent from the return
/// altitude at the landing speed (the slowest, so a deadline from it is never short).
double return_home_duration_s(const FlightLimits& l, double height_m, double distance_m);

}  // namespace eamos::mavlink_adapter
