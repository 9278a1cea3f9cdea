#pragma once
// The mavlink adapter's knobs: rates, budgets and waits, in mission seconds unless a field
// says wall seconds (register_adapter scales the wall-clock ones by --speed).
#include "mavlink_adapter/command_sender.h"

namespace eamos::mavlink_adapter {

struct MavlinkOptions {
  bool real_time = false;          ///< the loop runs in real time: required (a real vehicle
                                   ///< cannot follow virtual time)
  /// Mission seconds per wall second of the loop (--speed). The link's budgets below are
  /// wall-clock (network, scheduling), so register_adapter scales them by it; a vehicle sped
  /// up as much then gets the same slack in wall time as a real one.
  double speed = 1.0;
  double connect_timeout_s = 10.0; ///< wall seconds to wait for the vehicle's first HEARTBEAT
  /// Mission seconds without a HEARTBEAT = link lost. Mission time, not wall time: what
  /// matters is how far the vehicle flies unheard, and every action's deadline is mission
  /// time too, so a lost link is seen before the running motion's deadline at any --speed.
  double link_timeout_s = 3.0;
  /// ... but never less than this many wall seconds: the ground's own scheduling must not
  /// look like a lost link (0.5 s was too little: with --distributed and three PX4 SITL on a
  /// loaded 2-core machine all three links "dropped" at once). At --speed 5: 7.5 mission s,
  /// still before the deadline of a FlyBy of a few metres.
  double link_timeout_min_wall_s = 1.5;
  CommandOptions commands;         ///< ACK timeouts in wall seconds
  double setpoint_hz = 10.0;       ///< setpoint stream rate (PX4 needs > 2 Hz in OFFBOARD)
  int setpoints_before_switch = 5; ///< PX4: setpoints sent before asking for OFFBOARD
  double position_hz = 10.0;       ///< LOCAL_POSITION_NED rate asked for
  /// HEARTBEAT rate asked for: the armed flag travels only there, and a disarm (the
  /// autopilot's auto-disarm on the ground) must be seen within 100 ms, latency included.
  /// PX4 refuses it (LinkWatch::poll_heartbeat).
  double heartbeat_hz = 20.0;
  /// Wall seconds at connect to read the autopilot's speed parameters (PARAM_REQUEST_READ,
  /// resent every half second); what has not come by then keeps the fleet's limit.
  double param_timeout_s = 3.0;
  /// After an accepted mode switch, how long a HEARTBEAT in another mode still counts as sent
  /// before the switch took effect (seconds; scaled like the link's budgets).
  double mode_confirm_s = 3.0;
  /// ArduPilot queues the STATUSTEXT that explains a refusal and sends it after the
  /// COMMAND_ACK: a refused action waits this long for it (seconds; scaled).
  double statustext_wait_s = 0.5;
  /// A picture counts once the vehicle confirms it (CAMERA_TRIGGER, CAMERA_FEEDBACK or
  /// CAMERA_IMAGE_CAPTURED), not when the command is accepted: an autopilot accepts the
  /// command with no camera behind it. How long after the ACK to wait (seconds; scaled).
  double picture_confirm_s = 2.0;
  /// The fence upload (fleet `geofence: {upload: true}`): how long to wait for each answer of
  /// the autopilot before sending again (seconds; scaled like the link's budgets), and how
  /// many sends before it counts as silent.
  double fence_reply_s = 1.0;
  int fence_attempts = 5;
};

}  // namespace eamos::mavlink_adapter
