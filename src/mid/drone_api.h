#pragma once
// The Uniform Space's drone API (paper, section VI): one interface for every vehicle,
// whatever flies it. The DEX starts actions and reads properties through it only; each
// Adapter Space implementation (the simulator, src/sim; PX4 and ArduPilot over MAVLink,
// src/mavlink_adapter) hides its platform behind it.
//
// Rules every adapter keeps (the DEX relies on them):
//  - Every started action ends exactly once, as one Outcome, and its EndCallback always runs
//    later through the event loop: never inside start(), cancel() or failsafe().
//  - At most one motion action runs per drone: starting a motion action preempts the running
//    one, which ends `preempted`. Payload actions run beside motion; system actions (Arm,
//    Disarm) change the vehicle's state without moving it.
//  - The drone refuses what a real autopilot refuses (Takeoff while disarmed, Disarm in the
//    air, Arm with an empty battery, motion while disarmed): the action ends `failed` with
//    the reason in words. An action that exceeds its timeout (mid/timeouts.h) ends `failed`.
//  - Every `failed` end names its FailureReason (the same five kinds for every adapter); what
//    the vehicle itself said about it (an autopilot's MAV_RESULT and STATUSTEXT) is its detail.
//  - Hover() and Orbit() have no end of their own: they run until preempted or cancelled.
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fleet/fleet.h"
#include "mid/sensor_values.h"

namespace eamos::mid {

/// How an action ended.
enum class Outcome {
  succeeded,  ///< did what it was asked
  preempted,  ///< a newer motion action took over the vehicle (not an error)
  cancelled,  ///< stopped by cancel() or failsafe()
  failed,     ///< refused by the vehicle, timed out, or the vehicle could not complete it
};
const char* outcome_name(Outcome o);

/// Why an action ended `failed`, in the uniform API's words: a mission (and a person reading
/// its trace) can tell a refusal from a lost link whatever flies the vehicle. Preempted and
/// cancelled ends are not failures and carry `none`.
enum class FailureReason {
  none,             ///< the action did not fail
  refused,          ///< the drone or its autopilot would not do it (uniform rule, MAV_RESULT)
  timed_out,        ///< no end within its deadline, or the autopilot never answered the command
  link_lost,        ///< the link to the vehicle went silent
  vehicle_fault,    ///< the vehicle could not go on (battery empty, an autopilot failure)
  pilot_took_over,  ///< a pilot or the autopilot's own failsafe took the vehicle out of our control
};
/// "refused", "timed_out", "link_lost", "vehicle_fault", "pilot_took_over"; "" for none.
const char* failure_reason_name(FailureReason r);

/// A uniform action call, as the mission writes it: `FlyTo(1, 2, 3)` is {"FlyTo", {1, 2, 3}}.
/// Names and arities are the platform catalog's (fleet/catalog.h); a sensor read is "SensorK".
struct ActionRequest {
  std::string name;
  std::vector<double> args;
};

/// What an action's end reports.
struct ActionEnd {
  Outcome outcome = Outcome::succeeded;
  std::string reason;           ///< words for people: why it failed / who preempted it; "" on success
  std::optional<double> value;  ///< the reading of a succeeded SensorK action; empty otherwise
  FailureReason failure = FailureReason::none;  ///< set exactly when outcome is `failed`
  std::string detail;  ///< the vehicle's own words on a failure (MAV_RESULT, STATUSTEXT), or ""
};

/// The newest known properties of a drone: what the broker publishes and state() returns.
struct DroneState {
  double t = 0.0;        ///< mission time of these values, s
  double x = 0.0;        ///< m east of the mission origin
  double y = 0.0;        ///< m north of the mission origin
  double z = 0.0;        ///< m up, in the mission frame (ground at home is home.z, usually 0)
  double battery = 0.0;  ///< %
  bool armed = false;
  bool landed = true;
  SensorValues sensors;  ///< "Sensor1" … "SensorN" of the drone's type, in name order
  int pictures = 0;      ///< TakePicture actions that succeeded
  /// Degrees clockwise from north (0 ≤ heading < 360); NaN while the adapter does not know
  /// it. Telemetry for people (trace, monitor): no mission property reads it.
  double heading = std::numeric_limits<double>::quiet_NaN();
  std::string mode;      ///< the vehicle's flight mode in its own words ("OFFBOARD", "go"); "" unknown
  /// Nothing heard from the vehicle for its link timeout: the values above are the last
  /// known, and no command (not even a failsafe) reaches it until it is heard again.
  bool link_lost = false;
};

/// Where a vehicle stands on the Earth (WGS 84), as its autopilot reports it.
struct GlobalFix {
  double lat_deg = 0.0;
  double lon_deg = 0.0;
};

/// Identifies one started action of one drone; 0 (kNoAction) is never issued.
using ActionId = std::uint64_t;
inline constexpr ActionId kNoAction = 0;
/// Identifies one subscription to a drone's broker; 0 is never issued.
using SubscriptionId = std::uint64_t;

using EndCallback = std::function<void(const ActionEnd&)>;
using StateCallback = std::function<void(const DroneState&)>;

/// One vehicle. Adapters implement it; the DEX holds one per drone of the mission. All
/// methods are called from the event loop's thread; the loop must outlive the drone.
class Drone {
 public:
  virtual ~Drone() = default;

  /// The mission's name of the drone, e.g. "Drone1".
  virtual const std::string& name() const = 0;

  /// Starts an action; `on_end` runs exactly once, later, through the event loop. A refused
  /// action still gets an id and ends `failed`.
  virtual ActionId start(const ActionRequest& request, EndCallback on_end) = 0;
  /// Stops a running action, which ends `cancelled` (a stopped motion holds position).
  /// False when the action already ended or is unknown: its outcome stands.
  virtual bool cancel(ActionId id) = 0;
  /// How far a running action got, 0…1; empty when it ended, is unknown, or has no end of
  /// its own (Hover(), Orbit()).
  virtual std::optional<double> progress(ActionId) const { return std::nullopt; }

  /// The property broker's newest values.
  virtual DroneState state() const = 0;
  /// Calls `fn` with the state at the telemetry rate while the drone moves, and on every
  /// change of armed, landed or pictures; never from inside subscribe().
  virtual SubscriptionId subscribe(StateCallback fn) = 0;
  virtual void unsubscribe(SubscriptionId id) = 0;

  /// The mission failed: cancel every running action and land where the drone is, return
  /// home and land, or hover. After it the drone refuses new actions.
  virtual void failsafe(fleet::Failsafe what) = 0;

  /// Give way to another drone (dex/separation.h): stop the running goal-directed motion
  /// (FlyTo, FlyBy*, Takeoff, ReturnHome, Land) where the vehicle can stop, `climb_m` higher
  /// (negative: lower; 0: at its altitude), and keep the action running: it neither ends nor
  /// times out while held. False when no such motion runs, it is already held, or the
  /// vehicle cannot hold it (the autopilot flies it in a mode of its own).
  virtual bool hold_motion(double /*climb_m*/) { return false; }
  /// The held motion flies on to its own goal; its deadline moves on by the time it was
  /// held. False when nothing is held.
  virtual bool resume_motion() { return false; }
  /// Whether a motion is held now.
  virtual bool motion_held() const { return false; }
  /// How far (m) the running goal-directed motion still has to go, held or not; NaN when
  /// none runs or the adapter cannot tell. Separation ends a drone's predicted course there.
  virtual double motion_distance_left() const { return std::numeric_limits<double>::quiet_NaN(); }
  /// Where the running goal-directed motion goes (held or not), in the mission frame: its
  /// target (Land: the ground below; ReturnHome: home on the ground); empty when none runs
  /// or the adapter cannot tell. Separation predicts a drone that has one along the line to
  /// it, also while it still stands, rather than from its last two positions.
  virtual std::optional<fleet::Vec3> motion_goal() const { return std::nullopt; }

  /// Where the vehicle's own messages go (an autopilot's STATUSTEXT, what the adapter did
  /// about the vehicle on its own, such as re-arming after an auto-disarm): the DEX puts each
  /// in the trace. Called on the loop's thread; an empty function stops them. Default: none.
  virtual void set_message_sink(std::function<void(const std::string&)>) {}
  /// Where a fault of the drone itself goes that no running action carried (it left its
  /// geofence while it hovered between actions): `failed` with the reason, reported through
  /// the loop after the drone already commanded its failsafe. The DEX fails the mission on
  /// it as on a failed action. An empty function stops them. Default: none.
  virtual void set_fault_sink(std::function<void(const ActionEnd&)>) {}

  /// Whether the vehicle tells where it stands on the Earth (an autopilot with GPS); the
  /// built-in simulator has no such frame. Default: no.
  virtual bool has_global_frame() const { return false; }
  /// Its newest global position; empty until the vehicle has reported one (or never, without
  /// a global frame). The homes check (mid/home_check.h) compares these before arming.
  virtual std::optional<GlobalFix> global_fix() const { return std::nullopt; }
};

}  // namespace eamos::mid
