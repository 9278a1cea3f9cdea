// Orbit, two ways. PX4 flies MAV_CMD_DO_ORBIT itself in its Orbit mode; ArduPilot Copter has
// no DO_ORBIT, so there the adapter moves a position setpoint around the circle. Both circle
// like the simulator: centre where the orbit started, counter-clockwise seen from above, at
// the simulator's speed, until the action is preempted or cancelled.
#include <algorithm>
#include <cmath>

#include "mavlink/enums.h"
#include "mavlink_adapter/mavlink_drone.h"
#include "mid/vec.h"

namespace eamos::mavlink_adapter {

namespace ml = eamos::mavlink;
using fleet::Vec3;
using mid::ActionId;
using mid::Outcome;

namespace {
constexpr float kYawFrontToCentre = 0;  ///< ORBIT_YAW_BEHAVIOUR_HOLD_FRONT_TO_CIRCLE_CENTER
constexpr double kRadiusGain = 0.5;     ///< 1/s (2.0 was measured to oscillate, 4.5 .. 5.5 m)
}  // namespace

double MavlinkDrone::orbit_speed(double radius) const {
  // The simulator's: as fast as allowed while the centripetal acceleration keeps a margin,
  // within the slower of the fleet's and the autopilot's acceleration (ArduPilot
  // WPNAV_ACCEL, PX4 MPC_ACC_HOR). Above the autopilot's the vehicle cannot turn that tight:
  // on ArduCopter at 4 m/s (3.2 m/s² for 5 m, WPNAV_ACCEL 2.5) the orbit came out 4.72 m,
  // at 3.16 m/s 4.83 m before the radius correction below.
  const fleet::Limits& l = limits_.motion;
  return std::min(l.max_speed_mps, std::sqrt(0.8 * l.max_accel_mps2 * radius));
}

void MavlinkDrone::start_orbit(ActionId id, Vec3 centre, double radius) {
  // With DO_ORBIT the autopilot moves around the circle, not our setpoints: meanwhile (and
  // after a refusal) the stream holds the vehicle where it is.
  orbit_ = {!autopilot_->do_orbit, centre, radius, 0.0, false, false, false, radius};
  stream_setpoints();
  if (!autopilot_->do_orbit) return;
  // Radius negative = counter-clockwise; centre and altitude NaN = where the vehicle is;
  // param4 NaN = the autopilot's default number of turns (for ever).
  float r = static_cast<float>(radius);
  std::array<float, 7> p{-r, static_cast<float>(orbit_speed(radius)), kYawFrontToCentre,
                         NAN, NAN, NAN, NAN};
  send_mode_command(command(ml::cmd::DO_ORBIT, p), [this, id](const CommandResult& result) {
    if (!result.accepted) {
      if (motion_owner_ == id) orbit_ = {};
      if (tracker_.running(id)) end_refused(id, result);
      return;
    }
    if (motion_owner_ != id) return orbit_stopped_in_flight();
    streaming_ = false;
    in_control_ = false;
    orbit_.commanded = true;
    vehicle_.custom_mode = autopilot_->orbit_mode;  // until the next HEARTBEAT says otherwise
  });
}

void MavlinkDrone::orbit_stopped_in_flight() {
  // Cancelled or preempted while DO_ORBIT was on its way, and the autopilot took it after all.
  // If our setpoints fly the vehicle now, ask for the setpoint mode again; if a command
  // (Land, ReturnHome) came after it, the autopilot already left the orbit for that.
  if (!streaming_) return;
  in_control_ = false;
  vehicle_.custom_mode = autopilot_->orbit_mode;
}

void MavlinkDrone::leave_orbit() {
  // The hold mode at once, so the vehicle stops circling now, not after the setpoint stream
  // has earned the setpoint mode again (PX4: half a second of setpoints first).
  auto p = set_mode_params(*autopilot_, autopilot_->hold_mode);
  send_mode_command(command(ml::cmd::DO_SET_MODE, {p[0], p[1], p[2]}), nullptr);
  in_control_ = false;
}

bool MavlinkDrone::left_orbit_mode() {
  // Like the setpoint mode: someone else (a pilot, a failsafe) ended the autopilot's orbit.
  // Judged only once a HEARTBEAT has shown the orbit mode: one sent between the ACK and the
  // autopilot's next status may still show the mode from before.
  if (!orbit_.commanded || mode_commands_pending_ > 0) return false;
  if (vehicle_.custom_mode == autopilot_->orbit_mode) orbit_.mode_seen = true;
  if (!orbit_.mode_seen || vehicle_.custom_mode == autopilot_->orbit_mode) return false;
  ActionId id = motion_owner_;
  motion_owner_ = mid::kNoAction;
  orbit_ = {};
  std::string mode = mode_name(*autopilot_, vehicle_.custom_mode);
  tracker_.fail(id, mid::FailureReason::pilot_took_over,
                "the vehicle left " + mode_name(*autopilot_, autopilot_->orbit_mode) + " for " + mode, "mode " + mode);
  return true;
}

void MavlinkDrone::advance_orbit(double dt) {
  const double r = orbit_.radius;
  if (!orbit_.on_circle) {
    // Out to the circle's east point first, like the simulator, then around it.
    setpoint_ = {orbit_.centre.x + r, orbit_.centre.y, orbit_.centre.z};
    if (horizontal_norm(position() - setpoint_) <= options_.tolerance.horizontal_m) orbit_.on_circle = true;
    return;
  }
  // Moved by the vehicle's clock, which a SITL on a loaded machine runs slower than --speed:
  // moved by mission time, the setpoint would go round faster than the vehicle can turn.
  const double vehicle_dt = dt * std::clamp(vehicle_clock_rate(), 0.2, 2.0);
  orbit_.angle = std::fmod(orbit_.angle + orbit_speed(r) * vehicle_dt / r, 2.0 * M_PI);
  // A position setpoint moving around the circle is followed with a lag, along a chord:
  // ArduCopter circled at 4.5 m for 5 m. Feed-forward was tried and measured on ArduCopter
  // SITL, at the accel-bounded speed too: with velocity the orbit grew to 6.9 m, with
  // velocity and acceleration it shrank to 4.3 m and wobbled (3.6 .. 5.0 m), with velocity
  // setpoints steered by the measured radius it swung 4.6 .. 5.1 m. Position setpoints stay
  // the tightest. So the commanded radius is corrected by what the vehicle flies: an
  // integral on the radius error, within r … 1.5 r.
  if (vehicle_.have_position) {
    double flown = horizontal_norm(position() - orbit_.centre);
    orbit_.commanded_radius = std::clamp(orbit_.commanded_radius + kRadiusGain * dt * (r - flown), r, 1.5 * r);
  }
  const double rc = orbit_.commanded_radius;
  setpoint_ = {orbit_.centre.x + rc * std::cos(orbit_.angle),
               orbit_.centre.y + rc * std::sin(orbit_.angle), orbit_.centre.z};
}

}  // namespace eamos::mavlink_adapter
