#pragma once
// Orbit, two ways. PX4 flies MAV_CMD_DO_ORBIT itself in its Orbit mode; ArduPilot Copter has
// no DO_ORBIT, so there the setpoint stream moves around the circle. Both circle like the
// simulator: out to the circle's east point first, then counter-clockwise seen from above, at
// the simulator's speed, until the action is preempted or cancelled. Both correct the radius
// asked for by the one flown: ArduCopter's setpoints go round wider by the lag of its
// follower, PX4 is sent DO_ORBIT again with a corrected radius (correct_radius).
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "fleet/fleet.h"
#include "mavlink_adapter/command_sender.h"
#include "mavlink_adapter/mode_commands.h"
#include "mavlink_adapter/setpoint_stream.h"
#include "mavlink_adapter/telemetry.h"
#include "mavlink_adapter/vehicle_clock.h"
#include "mavlink_adapter/vehicle_link.h"
#include "mid/drone_api.h"

namespace eamos::mavlink_adapter {

class OrbitFlight {
 public:
  struct Hooks {
    std::function<void(const std::string&)> note;  ///< to the trace
    /// The autopilot refused (or never answered) DO_ORBIT for the Orbit `id`.
    std::function<void(mid::ActionId id, const CommandResult&)> refused;
    /// Somebody else (a pilot, a failsafe) took the vehicle out of the autopilot's orbit.
    std::function<void(const std::string& reason, const std::string& detail)> left;
  };
  OrbitFlight(const fleet::DroneSettings& settings, VehicleLink& link, VehicleState& vehicle,
              const VehicleClock& clock, SetpointStream& stream, ModeCommands& modes, CommandSender& commands,
              Hooks hooks);

  /// "" when the autopilot flies an orbit of `radius`; else why not (PX4: 1 m to MC_ORBIT_RAD_MAX).
  std::string radius_refusal(double radius) const;
  /// The Orbit `id` around `centre`: out to the circle on our setpoints first.
  void start(mid::ActionId id, fleet::Vec3 centre, double radius);
  /// No orbit any more (another motion, a failure); the vehicle is left as it is.
  void reset();
  /// The Orbit stopped (cancelled, preempted): an autopilot orbiting is put in its hold mode.
  void stop();
  /// The autopilot flies the orbit (DO_ORBIT taken), not our setpoints.
  bool commanded() const { return orbit_.commanded; }
  /// For the setpoint stream's each tick: moves the setpoint round; the heading to face.
  std::optional<double> steer(double dt);
  /// On a GLOBAL_POSITION_INT: the radius flown, for the correction.
  void on_global_position();
  /// On an autopilot HEARTBEAT: true when it left its orbit mode (the orbit failed, `left`
  /// was called); else the radius correction goes if one is due.
  bool on_heartbeat();

 private:
  struct State {
    bool active = false;
    fleet::Vec3 centre;
    double radius = 0.0;
    double angle = 0.0;     ///< rad from east, counter-clockwise
    bool on_circle = false;
    bool commanded = false; ///< the autopilot flies it (DO_ORBIT accepted), not our setpoints
    bool mode_seen = false; ///< a HEARTBEAT has shown the autopilot's orbit mode
    double commanded_radius = 0.0;  ///< our setpoints' (or DO_ORBIT's) radius: `radius`
                                    ///< corrected by the radius flown
    // DO_ORBIT's radius correction (correct_radius)
    double sent_radius = 0.0;       ///< the radius the autopilot flies to, as last sent
    double sent_speed = 0.0;        ///< ... and its speed
    double flown_speed = 0.0;       ///< along the circle, smoothed like last_flown_m
    double outward_mps = 0.0;       ///< how fast the radius flown grows, smoothed
    double previous_flown_m = 0.0;  ///< the radius flown at the previous report
    double sent_at_s = 0.0;         ///< vehicle s the last correction was sent
    double last_report_s = -1.0;    ///< vehicle s of the previous GLOBAL_POSITION_INT
    double last_flown_m = 0.0;      ///< the radius flown, smoothed over kFlownSmoothingS
    double recent_flown_m = 0.0;    ///< ... smoothed over kRecentSmoothingS only
    bool correcting = false;        ///< a correction waits for its COMMAND_ACK
    bool corrections_stopped = false;  ///< one was refused (or never answered): no more
    /// The centre in degE7, named to PX4 in DO_ORBIT (centre_known: a global position was at
    /// hand when the orbit started).
    bool centre_known = false;
    int32_t centre_lat_e7 = 0, centre_lon_e7 = 0;
    bool do_orbit_sent = false;
    bool centre_compared = false;  ///< the autopilot's centre has been traced beside ours
    double waited_at_start_s = 0.0;  ///< mission s at the east point, waiting to be still
  };

  const Autopilot& autopilot() const { return *link_.autopilot(); }
  fleet::Vec3 position() const { return mission_position(vehicle_, settings_.home); }
  double orbit_speed(double radius) const;
  double near_start_m() const;
  void advance(double dt);
  bool done_moving_out() const;
  /// PX4, out to its circle on our setpoints: the heading (rad from north) that faces the centre.
  std::optional<double> setpoint_yaw() const;
  bool faces_centre() const;  ///< within kFacingDeg, or the heading is not known
  /// PX4: DO_ORBIT around the centre, from where the vehicle is.
  void send_do_orbit();
  void do_orbit_taken();
  std::array<float, 7> do_orbit_params(double radius, double speed) const;
  void stopped_in_flight();
  void leave();
  bool left_mode();  ///< the vehicle left DO_ORBIT's mode: the orbit failed
  void correct_radius();
  double led_radius() const;  ///< the radius a correction sends, before its bounds
  void trace_centre();
  void send_due_correction();

  const fleet::DroneSettings& settings_;
  VehicleLink& link_;
  VehicleState& vehicle_;
  const VehicleClock& clock_;
  SetpointStream& stream_;
  ModeCommands& modes_;
  CommandSender& commands_;
  Hooks hooks_;
  State orbit_;  ///< active: our setpoints fly it; commanded: the autopilot does
  mid::ActionId id_ = mid::kNoAction;  ///< the Orbit action
  /// Counts starts and resets: a command's answer for an orbit since replaced is not this one's.
  uint64_t epoch_ = 0;
};

}  // namespace eamos::mavlink_adapter
