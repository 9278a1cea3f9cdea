#pragma once
// The position setpoint stream (SET_POSITION_TARGET_LOCAL_NED at setpoint_hz) and the
// setpoint mode it needs (PX4 OFFBOARD, ArduPilot GUIDED). The stream asks for the mode once
// it runs (PX4: after setpoints_before_switch setpoints, or OFFBOARD is refused); once the
// vehicle is in it, leaving it is somebody else's doing (a pilot, a failsafe), and the stream
// gives way instead of switching back. While the autopilot flies a command in its own mode
// (takeoff, land, return, DO_ORBIT) the stream is handed over and silent.
#include <functional>
#include <optional>

#include "fleet/fleet.h"
#include "mavlink_adapter/link_watch.h"
#include "mavlink_adapter/mode_commands.h"
#include "mavlink_adapter/setpoint_pacer.h"
#include "mavlink_adapter/telemetry.h"
#include "mavlink_adapter/vehicle_link.h"
#include "mid/event_loop.h"

namespace eamos::mavlink_adapter {

class SetpointStream {
 public:
  struct Hooks {
    /// Before each setpoint: moves it (an orbit going round) and says the heading to hold
    /// (rad from north), if any.
    std::function<std::optional<double>(double dt)> steer;
    /// The autopilot refused (or never answered) the switch to the setpoint mode.
    std::function<void(const CommandResult&)> refused;
  };
  SetpointStream(mid::EventLoop& loop, const MavlinkOptions& options, const fleet::DroneSettings& settings,
                 VehicleLink& link, ModeCommands& modes, const VehicleState& vehicle, const LinkWatch& watch,
                 Hooks hooks);
  ~SetpointStream();
  SetpointStream(const SetpointStream&) = delete;
  SetpointStream& operator=(const SetpointStream&) = delete;

  /// Where the setpoints go (mission frame); the running stream takes it at its next tick.
  void aim(fleet::Vec3 target) { setpoint_ = target; }
  const fleet::Vec3& target() const { return setpoint_; }
  /// Streams (again) from now on.
  void start();
  void hold(fleet::Vec3 target) {
    aim(target);
    start();
  }
  /// The setpoints stop; the mode asked for is kept.
  void stop() { streaming_ = false; }
  /// The vehicle is no longer in the setpoint mode for us: a stream asks for it again.
  void lose_control() { in_control_ = false; }
  /// The autopilot flies in its own mode now: no setpoints, no claim on the mode.
  void hand_over() {
    stop();
    lose_control();
  }
  bool streaming() const { return streaming_; }
  /// On a HEARTBEAT: true when somebody else took the vehicle out of the setpoint mode while
  /// we held it (the stream has handed over then).
  bool taken_away();

 private:
  void tick();
  void switch_to_setpoint_mode();

  mid::EventLoop& loop_;
  const MavlinkOptions& options_;
  const fleet::DroneSettings& settings_;
  VehicleLink& link_;
  ModeCommands& modes_;
  const VehicleState& vehicle_;
  const LinkWatch& watch_;
  Hooks hooks_;
  bool streaming_ = false;        ///< setpoints are the vehicle's control (else: its own modes)
  bool in_control_ = false;       ///< the vehicle entered the setpoint mode for our stream; if
                                  ///< it leaves it (a pilot, a failsafe), we do not fight it
  /// A HEARTBEAT has shown the setpoint mode since we last asked for it. Until then a
  /// HEARTBEAT in another mode is one sent before the switch took effect (PX4 acknowledges
  /// DO_SET_MODE a cycle before its mode changes), not somebody taking over.
  bool mode_confirmed_ = false;
  double mode_granted_at_ = 0.0;  ///< loop time the setpoint mode was last granted
  fleet::Vec3 setpoint_;          ///< mission frame
  SetpointPacer pacer_;  ///< the site's speed limits on what is sent (setpoint_pacer.h)
  int sent_ = 0;                  ///< setpoints since the stream (re)started
  mid::TimerId timer_ = mid::kNoTimer;
};

}  // namespace eamos::mavlink_adapter
