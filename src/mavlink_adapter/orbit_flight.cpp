// How the orbit is flown, and why each bound is what it is. The figures in the comments
// were measured on ArduCopter SITL and PX4 SITL (SIH) flying Listing 2's orbit of 5 m.
#include "mavlink_adapter/orbit_flight.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>
#include <utility>

#include "mavlink/enums.h"
#include "mid/vec.h"

namespace eamos::mavlink_adapter {

namespace ml = eamos::mavlink;
using fleet::Vec3;
using mid::ActionId;

namespace {
constexpr float kYawFrontToCentre = 0;  ///< ORBIT_YAW_BEHAVIOUR_HOLD_FRONT_TO_CIRCLE_CENTER
/// ArduCopter SITL followed setpoints going round 5 m at 4.5 m: a follower lagging by tau cuts
/// a circle flown at angular rate w in by 1 / sqrt(1 + (w tau)^2), so the setpoints go round
/// that much wider, w from the vehicle's own speed up to the orbit's (beyond, a vehicle that
/// follows closely would be led ever wider by its own speed). The lead grows with the
/// vehicle's speed rather than being fixed from the start: a fixed lead holds the vehicle out
/// while it speeds up, and the integral, wound down against that, then carries it inside the
/// circle half a turn later.
constexpr double kFollowerLagS = 0.9;
constexpr double kRadiusGain = 0.25;  ///< 1/s: what the lead leaves (0.5: 4.80 .. 5.14 m; 2.0 oscillated)
// DO_ORBIT's correction. PX4 re-approaches its circle when a new radius is more than its
// acceptance radius (FlightTaskOrbit: 1 m) from where the vehicle is: each step stays well
// inside it, so the vehicle keeps circling while the radius moves.
// The correction is a PD loop on top of PX4's own radial term (1 /s): PX4 flies
// (sent − flown) outward, so sending r + 2 (r − flown) − 1 s × (outward speed) makes its
// radial law three times as stiff and damped. The outward speed is the change of the distance
// itself: GLOBAL_POSITION_INT's velocity, projected, read −0.25 m/s while the distance stood
// still (the EKF's velocity and position disagree by that much as the vehicle speeds up). The
// integral only takes out what is left over a turn: a faster one (0.25 /s) lags PX4's
// once-a-turn swing by a quarter turn and feeds it. Five corrections a vehicle second (the
// HEARTBEAT is polled for it, LinkWatch::poll_heartbeat): fewer, the loop trails the swing it corrects.
// The integral runs from the start: held back while the vehicle speeds up, it would leave the
// mean up to 0.2 m off for most of a short orbit.
constexpr double kDoOrbitGain = 0.2;        ///< 1/s of vehicle time, on the radius error
constexpr double kCorrectionEveryS = 0.2;   ///< at most five DO_ORBITs per vehicle second
constexpr double kSmallestStepM = 0.03;     ///< a smaller change is not worth a command
constexpr double kLargestStepM = 0.3;
constexpr double kDoOrbitLead = 2.0;        ///< m of radius sent per m flown off the circle
constexpr double kDoOrbitDampingS = 1.0;    ///< m of radius sent per m/s moving outward
constexpr double kRecentSmoothingS = 0.15;
constexpr double kOutwardSmoothingS = 0.3;
constexpr double kAwayFromFlownM = 0.6;     ///< the radius sent stays this near the one flown
constexpr double kOnCircleM = 1.0;          ///< PX4 circles from this close to the radius on
constexpr double kSettledRadialMps = 0.3;   ///< ... and we correct once it no longer moves out
constexpr double kFlownSmoothingS = 2.0;    ///< the radius flown, as the trace reports it
// PX4 applies the centripetal feed-forward of the speed it is given at once, while the
// vehicle still stands and speeds up slowly (0.2 m/s² on SIH): at 3.5 m/s asked for 5 m the
// circle sank to 4.5 m within 2 s of the start and swung out to 5.5 m after. So it is given a
// speed above the one it flies, raised slot by slot to the orbit's. The lead is a balance:
// the vehicle's velocity lags its turning setpoint, which carries it outward, while the
// feed-forward of a speed above the one flown pulls it in. 0.5 m/s above: drifted 0.3-0.6 m
// out in the first 2 s; 1.0 m/s above: 0.1-0.3 m in, and twice as fast around (2 m/s).
constexpr double kSpeedLeadMps = 1.0;
constexpr double kSpeedSmoothingS = 0.5;
// DO_ORBIT waits at the east point for the vehicle to come to rest there, facing the centre.
constexpr double kStartStillMps = 0.08;     ///< DO_ORBIT once the vehicle is this still ...
constexpr double kStartOnCircleM = 0.15;    ///< ... this close to the circle ...
constexpr double kFacingDeg = 10.0;         ///< ... turned this near to the centre ...
constexpr double kStartWaitS = 1.5;         ///< ... or has waited this long (mission s) there,
constexpr double kStartOutwardMps = 0.08;   ///< ... and on PX4 no longer moves out this fast,
constexpr double kStartWaitMostS = 5.0;     ///< ... or has waited this long
}  // namespace

OrbitFlight::OrbitFlight(const fleet::DroneSettings& settings, VehicleLink& link, VehicleState& vehicle,
                         const VehicleClock& clock, SetpointStream& stream, ModeCommands& modes,
                         CommandSender& commands, Hooks hooks)
    : settings_(settings),
      link_(link),
      vehicle_(vehicle),
      clock_(clock),
      stream_(stream),
      modes_(modes),
      commands_(commands),
      hooks_(std::move(hooks)) {}

// PX4 orbits from 1 m to MC_ORBIT_RAD_MAX. The vehicle first flies out to the circle
// (start), so a radius PX4 would refuse is refused before it moves, not at the circle.
std::string OrbitFlight::radius_refusal(double radius) const {
  char text[160];
  if (radius < 1.0) {
    std::snprintf(text, sizeof text, "orbit radius %.1f m is below the smallest %s flies (1 m)", radius,
                  autopilot().name);
    return text;
  }
  const double largest = link_.limits().orbit_radius_max_m;
  if (largest <= 0.0 || radius <= largest) return "";
  std::snprintf(text, sizeof text, "orbit radius %.1f m is above %s's MC_ORBIT_RAD_MAX %.0f m", radius,
                autopilot().name, largest);
  return text;
}



// How near the east point the wait for the orbit's start begins. PX4 circles from where it
// is, and its OFFBOARD hold can stand 0.6-0.7 m off the east point for seconds (its estimate of
// velocity and position disagreeing): judged by the goal tolerance (0.5 m), the wait might not
// begin for 10 s, and a short orbit (Listing 2's, ended by the others' landing) would be mostly
// spent waiting. Within PX4's own acceptance radius (kOnCircleM) it begins; our setpoint orbit
// (ArduCopter) starts at the goal tolerance.
double OrbitFlight::near_start_m() const {
  return autopilot().do_orbit ? std::max(kOnCircleM, settings_.tolerance.horizontal_m)
                              : settings_.tolerance.horizontal_m;
}

double OrbitFlight::orbit_speed(double radius) const {
  // The simulator's: as fast as allowed while the centripetal acceleration keeps a margin,
  // within the slower of the fleet's and the autopilot's acceleration (ArduPilot
  // WPNAV_ACCEL, PX4 MPC_ACC_HOR). Above the autopilot's the vehicle cannot turn that tight:
  // on ArduCopter at 4 m/s (3.2 m/s² for 5 m, WPNAV_ACCEL 2.5) the orbit came out 4.72 m,
  // at 3.16 m/s 4.83 m before the radius correction below.
  const fleet::Limits& l = link_.limits().motion;
  return std::min(l.max_speed_mps, std::sqrt(0.8 * l.max_accel_mps2 * radius));
}

void OrbitFlight::start(ActionId id, Vec3 centre, double radius) {
  // Out to the circle's east point on our setpoints first, like the simulator; from there
  // ArduCopter goes round on our setpoints, PX4 by itself (send_do_orbit).
  id_ = id;
  ++epoch_;
  orbit_ = {true, centre, radius, 0.0, false, false, false, radius};
  orbit_.sent_radius = radius;
  char text[128];
  std::snprintf(text, sizeof text, "orbit of %.2f m around x %.2f, y %.2f", radius, centre.x, centre.y);
  hooks_.note(text);  // where the vehicle circles, for a reader of the trace (and the SITL tests)
  // Named to PX4 in degrees, converted when DO_ORBIT goes (send_do_orbit).
  orbit_.centre_known = autopilot().do_orbit && vehicle_.have_altitude;
  // Without a global position the centre cannot be named to PX4: it orbits where the vehicle
  // is, from there (its own approach out to the circle overshoots it by up to 0.7 m).
  if (autopilot().do_orbit && !orbit_.centre_known) return send_do_orbit();
  stream_.start();
}

void OrbitFlight::reset() {
  ++epoch_;
  orbit_ = {};
}

void OrbitFlight::stop() {
  bool autopilot_orbits = orbit_.commanded;
  reset();
  if (autopilot_orbits) leave();
}

std::optional<double> OrbitFlight::steer(double dt) {
  if (orbit_.active) advance(dt);
  return setpoint_yaw();
}

void OrbitFlight::on_global_position() {
  if (orbit_.commanded) correct_radius();
}

bool OrbitFlight::on_heartbeat() {
  if (left_mode()) return true;
  send_due_correction();
  return false;
}

// PX4 circles from where it is when DO_ORBIT comes: started at the centre, its approach is
// its circle's radial term from 5 m off, which overshot to 5.7 m and swung 4.4 .. 5.7 m on a
// loaded SITL. Started on the circle, with the centre named (COMMAND_INT, degE7), it only
// speeds up along it.
void OrbitFlight::send_do_orbit() {
  orbit_.do_orbit_sent = true;
  auto done = [this, id = id_, epoch = epoch_](const CommandResult& result) {
    if (!result.accepted) {
      if (epoch == epoch_) reset();
      hooks_.refused(id, result);
      return;
    }
    if (epoch != epoch_) return stopped_in_flight();
    do_orbit_taken();
  };
  // From the centre PX4 flies out first (no standstill on the circle): the orbit's speed at once.
  orbit_.sent_speed = orbit_.centre_known ? std::min(kSpeedLeadMps, orbit_speed(orbit_.radius)) : orbit_speed(orbit_.radius);
  if (!orbit_.centre_known)
    return modes_.send(link_.command(ml::cmd::DO_ORBIT, do_orbit_params(orbit_.radius, orbit_.sent_speed)), done);
  // The centre in degrees from where the vehicle is now, standing still on its circle:
  // GLOBAL_POSITION_INT and LOCAL_POSITION_NED are separate reports, and converted from a
  // vehicle still moving (as when the Orbit starts after a FlyTo) their skew put PX4's circle
  // 0.1-0.2 m off the centre in the vehicle's local frame.
  const Vec3 off = orbit_.centre - position();
  std::tie(orbit_.centre_lat_e7, orbit_.centre_lon_e7) = offset_lat_lon(vehicle_.lat_e7, vehicle_.lon_e7, off.y, off.x);
  // The radius asked for, not the one the vehicle stands on. The move out winds PX4's velocity
  // integrator up outward (SIH's drag, 1 /s, taken up on the way), and OFFBOARD holds the
  // vehicle 0.2-0.4 m beyond the east point against it, its position term pulling inward.
  // Given the circle it stood on, PX4's radial term pulled nothing and the integrator carried
  // the vehicle 0.3-0.5 m further out; given the radius, the pull stays as it was.
  orbit_.sent_radius = orbit_.radius;
  auto p = do_orbit_params(orbit_.sent_radius, orbit_.sent_speed);
  ml::CommandInt c;
  c.target_system = link_.sysid();
  c.target_component = ml::comp::AUTOPILOT1;
  c.frame = ml::kFrameGlobal;  // z NaN: the altitude it has
  c.command = ml::cmd::DO_ORBIT;
  c.param = {p[0], p[1], p[2], p[3]};
  c.x = orbit_.centre_lat_e7, c.y = orbit_.centre_lon_e7;
  c.z = NAN;
  modes_.send(c, done);
}

void OrbitFlight::do_orbit_taken() {
  stream_.hand_over();
  orbit_.active = false;  // PX4 moves around the circle now, not our setpoints
  orbit_.on_circle = false;  // for the radius correction: PX4's own word on its circle
  orbit_.commanded = true;
  vehicle_.have_orbit_centre = false;  // a report from before is of an orbit before this one
  if (!orbit_.centre_known && vehicle_.have_position) orbit_.centre = position();
  vehicle_.custom_mode = autopilot().orbit_mode;  // until the next HEARTBEAT says otherwise
}

std::array<float, 7> OrbitFlight::do_orbit_params(double radius, double speed) const {
  // Radius negative = counter-clockwise; centre and altitude NaN = where the vehicle is when
  // PX4 enters its Orbit mode, and, sent again in that mode, the centre it has: only radius
  // and speed change. param4 NaN = the autopilot's default number of turns (for ever). The
  // speed is at most the one of the radius asked for (PX4 lowers it to what it can turn at).
  return {-static_cast<float>(radius), static_cast<float>(speed), kYawFrontToCentre, NAN, NAN, NAN, NAN};
}

void OrbitFlight::stopped_in_flight() {
  // Cancelled or preempted while DO_ORBIT was on its way, and the autopilot took it after all.
  // If our setpoints fly the vehicle now, ask for the setpoint mode again; if a command
  // (Land, ReturnHome) came after it, the autopilot already left the orbit for that.
  if (!stream_.streaming()) return;
  stream_.lose_control();
  vehicle_.custom_mode = autopilot().orbit_mode;
}

void OrbitFlight::leave() {
  // The hold mode at once, so the vehicle stops circling now, not after the setpoint stream
  // has earned the setpoint mode again (PX4: half a second of setpoints first).
  auto p = set_mode_params(autopilot(), autopilot().hold_mode);
  modes_.send(link_.command(ml::cmd::DO_SET_MODE, {p[0], p[1], p[2]}), nullptr);
  stream_.lose_control();
}

bool OrbitFlight::left_mode() {
  // Like the setpoint mode: someone else (a pilot, a failsafe) ended the autopilot's orbit.
  // Judged only once a HEARTBEAT has shown the orbit mode: one sent between the ACK and the
  // autopilot's next status may still show the mode from before.
  if (!orbit_.commanded || modes_.pending()) return false;
  if (vehicle_.custom_mode == autopilot().orbit_mode) orbit_.mode_seen = true;
  if (!orbit_.mode_seen || vehicle_.custom_mode == autopilot().orbit_mode) return false;
  reset();
  std::string mode = mode_name(autopilot(), vehicle_.custom_mode);
  hooks_.left("the vehicle left " + mode_name(autopilot(), autopilot().orbit_mode) + " for " + mode, "mode " + mode);
  return true;
}

void OrbitFlight::advance(double dt) {
  const double r = orbit_.radius;
  if (!orbit_.on_circle) {
    // Out to the circle's east point first, like the simulator, then around it.
    stream_.aim({orbit_.centre.x + r, orbit_.centre.y, orbit_.centre.z});
    if (horizontal_norm(position() - stream_.target()) > near_start_m()) return;
    // Round from a standstill there. PX4 (send_do_orbit starts it on the circle): its radial
    // term is slow, and a vehicle still drifting out at 0.15-0.3 m/s when DO_ORBIT came went on
    // 0.3-0.6 m past its circle. ArduCopter, started as it came within the tolerance (still
    // moving out at 0.7 m/s), went on 0.25 m past it. A vehicle that does not come to rest (a
    // gusty hold) starts after kStartWaitS all the same.
    if (orbit_.do_orbit_sent) return;
    orbit_.waited_at_start_s += dt;
    if (autopilot().do_orbit && !done_moving_out()) return;
    const bool still = norm(vehicle_.ned_velocity) <= kStartStillMps &&
                       std::fabs(horizontal_norm(position() - orbit_.centre) - r) <= kStartOnCircleM &&
                       faces_centre();
    if (!still && (orbit_.waited_at_start_s < kStartWaitS || norm(vehicle_.ned_velocity) > settings_.tolerance.settled_mps))
      return;
    if (autopilot().do_orbit) return send_do_orbit();
    orbit_.on_circle = true;
    return;
  }
  // Moved by the vehicle's clock, which a SITL on a loaded machine runs slower than --speed:
  // moved by mission time, the setpoint would go round faster than the vehicle can turn.
  const double vehicle_dt = dt * std::clamp(clock_.rate(), 0.2, 2.0);
  orbit_.angle = std::fmod(orbit_.angle + orbit_speed(r) * vehicle_dt / r, 2.0 * M_PI);
  // A position setpoint moving around the circle is followed with a lag, along a chord:
  // ArduCopter circled at 4.5 m for 5 m. No feed-forward: on ArduCopter SITL, at the
  // accel-bounded speed, velocity feed-forward grows the orbit to 6.9 m, velocity and
  // acceleration shrink it to 4.3 m with a wobble of 3.6 .. 5.0 m, and velocity setpoints
  // steered by the measured radius swing 4.6 .. 5.1 m (GUIDED integrates its own target between
  // our setpoints and its jerk-limited shaping chases each new one). Position setpoints are the
  // tightest, so they go round wider by the lag the vehicle's speed gives, and an integral on
  // the radius error takes out what is left.
  if (vehicle_.have_position) {
    double flown = horizontal_norm(position() - orbit_.centre);
    orbit_.commanded_radius =
        std::clamp(orbit_.commanded_radius + kRadiusGain * dt * (r - flown), 0.6 * r, 1.5 * r);
  }
  const double w = std::min(horizontal_norm(vehicle_.ned_velocity), orbit_speed(r)) / r;
  const double rc = orbit_.commanded_radius * std::sqrt(1.0 + w * w * kFollowerLagS * kFollowerLagS);
  stream_.aim({orbit_.centre.x + rc * std::cos(orbit_.angle), orbit_.centre.y + rc * std::sin(orbit_.angle),
                orbit_.centre.z});
}

// PX4 SITL arrives at the east point overshooting it by 0.2-0.45 m (its velocity integrator,
// wound up against SIH's drag on the move out, carries it on while it brakes), and its
// estimator's velocity can read under the goal's 0.3 m/s while the position still moves out
// at 0.3-0.7 m/s. DO_ORBIT sent within the overshoot lets the vehicle carry on outward, still
// 0.3 m out of its circle 2 s later. So the start waits, by the vehicle's positions over the
// last half second, until the distance from the centre no longer grows, at most
// kStartWaitMostS.
bool OrbitFlight::done_moving_out() const {
  if (orbit_.waited_at_start_s >= kStartWaitMostS) return true;
  const double span_s = vehicle_.track_span_s();
  if (span_s <= 0.0) return true;
  auto distance = [this](const Vec3& ned) {
    return horizontal_norm(ned_to_mission(ned, settings_.home) - orbit_.centre);
  };
  const auto& track = vehicle_.track;
  return (distance(track.back().second) - distance(track.front().second)) / span_s <= kStartOutwardMps;
}

// DO_ORBIT turns PX4's front to the centre (kYawFrontToCentre). Turned there from the takeoff's
// heading as the orbit begins, a quarter turn at PX4's yaw rate limit while the vehicle speeds
// up, the circle sinks 0.2-0.3 m in its first seconds (to 4.68-4.81 m for 5); turned on the
// way out, it does not. ArduCopter's setpoint orbit keeps its heading: no yaw is sent there.
std::optional<double> OrbitFlight::setpoint_yaw() const {
  if (!orbit_.active || !autopilot().do_orbit) return std::nullopt;
  const Vec3 to_centre = orbit_.centre - stream_.target();  // mission frame: x east, y north
  if (horizontal_norm(to_centre) < 0.1) return std::nullopt;  // no direction to face
  return std::atan2(to_centre.x, to_centre.y);
}

bool OrbitFlight::faces_centre() const {
  const std::optional<double> yaw = setpoint_yaw();
  if (!yaw || vehicle_.heading_deg < 0) return true;
  return std::fabs(std::remainder(vehicle_.heading_deg - *yaw * 180.0 / M_PI, 360.0)) <= kFacingDeg;
}

// PX4's orbit is a velocity controller (tangential speed, a radial term on the radius error,
// centripetal feed-forward): its circle is smooth but, measured on SITL, 4.12-5.10 m for 5 m,
// different from run to run and with the machine's load. As on ArduCopter, the radius asked
// for is corrected by the one flown, an integral on the error, here sent as DO_ORBIT again
// with the centre left NaN. The radius flown is the distance from the centre PX4 reports
// (ORBIT_EXECUTION_STATUS), measured in GLOBAL_POSITION_INT's frame, not a circle fitted to
// the last half turn: such a fit swings 4.3 .. 6.1 m while the vehicle flies 4.6 .. 5.4 m.
// Without the autopilot's centre, the one it was given (start); without either, no
// correction: PX4's own circle is better than one corrected by a wrong measure.
void OrbitFlight::correct_radius() {
  State& o = orbit_;
  const double vehicle_s = vehicle_.global_time_boot_ms / 1000.0;
  const double dt = o.last_report_s < 0 ? 0.0 : vehicle_s - o.last_report_s;
  o.last_report_s = vehicle_s;
  if (o.corrections_stopped) return;
  // The centre PX4 says it circles, else the one it was given.
  const bool said = vehicle_.have_orbit_centre;
  if (!said && !o.centre_known) return;
  if (said && o.centre_known && !o.centre_compared) trace_centre();
  const Vec3 out = north_east_between(said ? vehicle_.orbit_centre_lat_e7 : o.centre_lat_e7,
                                      said ? vehicle_.orbit_centre_lon_e7 : o.centre_lon_e7, vehicle_.lat_e7,
                                      vehicle_.lon_e7);
  const double flown = std::hypot(out.x, out.y);
  const Vec3& v = vehicle_.global_velocity;
  const double outward = flown > 0.0 ? (v.x * out.x + v.y * out.y) / flown : 0.0;
  const double along = std::sqrt(std::max(0.0, v.x * v.x + v.y * v.y - outward * outward));
  if (!o.on_circle) {
    // Out from the centre first (PX4's circle approach): an error meanwhile is no error.
    if (std::fabs(flown - o.radius) > kOnCircleM || outward > kSettledRadialMps) return;
    o.on_circle = true;
    o.sent_at_s = vehicle_s;
    o.last_flown_m = o.recent_flown_m = o.previous_flown_m = flown;
    return;
  }
  const double previous_flown = o.previous_flown_m;
  o.previous_flown_m = flown;
  if (dt <= 0.0 || dt > 1.0) return;  // a gap or a report out of order: nothing to integrate over
  o.last_flown_m += std::min(1.0, dt / kFlownSmoothingS) * (flown - o.last_flown_m);
  o.recent_flown_m += std::min(1.0, dt / kRecentSmoothingS) * (flown - o.recent_flown_m);
  o.flown_speed += std::min(1.0, dt / kSpeedSmoothingS) * (along - o.flown_speed);
  o.outward_mps += std::min(1.0, dt / kOutwardSmoothingS) * ((flown - previous_flown) / dt - o.outward_mps);
  // Not while the lead is at its bound: integrated while the lead pulled the vehicle back from
  // 0.4 m off, the integral carried it 0.5 m past the circle.
  const double led = led_radius();
  if (std::fabs(led - o.recent_flown_m) >= kAwayFromFlownM) return;
  o.commanded_radius =
      std::clamp(o.commanded_radius + kDoOrbitGain * dt * (o.radius - flown), 0.8 * o.radius, 1.5 * o.radius);
}

// The radius to send: the integral, led by how far off the circle the vehicle is and damped
// by how fast it moves out.
double OrbitFlight::led_radius() const {
  const State& o = orbit_;
  return o.commanded_radius + kDoOrbitLead * (o.radius - o.recent_flown_m) - kDoOrbitDampingS * o.outward_mps;
}

// Where PX4 circles may differ from the centre it was given (its own projection, a position
// that moved between the two reports the centre was computed from): said once, for a reader
// of the trace judging the circle flown.
void OrbitFlight::trace_centre() {
  orbit_.centre_compared = true;
  const Vec3 off = north_east_between(orbit_.centre_lat_e7, orbit_.centre_lon_e7, vehicle_.orbit_centre_lat_e7,
                                      vehicle_.orbit_centre_lon_e7);
  char text[128];
  std::snprintf(text, sizeof text, "the autopilot circles %.2f m north, %.2f m east of the centre it was given",
                off.x, off.y);
  hooks_.note(text);
}

// Sent only right after a HEARTBEAT that shows the Orbit mode: DO_ORBIT in any other mode
// makes PX4 enter Orbit, and one that crossed a pilot's mode switch would take the vehicle
// back from the pilot. Right after the HEARTBEAT that window is the link's latency, not the
// heartbeat period.
void OrbitFlight::send_due_correction() {
  State& o = orbit_;
  if (!o.commanded || !o.on_circle || o.corrections_stopped || o.correcting || !o.mode_seen) return;
  if (vehicle_.custom_mode != autopilot().orbit_mode || modes_.pending()) return;
  if (o.last_flown_m <= 0.0 || o.last_report_s - o.sent_at_s < kCorrectionEveryS) return;
  const double speed = std::min(orbit_speed(o.radius), std::max(o.sent_speed, o.flown_speed + kSpeedLeadMps));
  // Within PX4's acceptance radius of where the vehicle is, else it re-approaches its circle.
  const double led = std::clamp(led_radius(), o.recent_flown_m - kAwayFromFlownM, o.recent_flown_m + kAwayFromFlownM);
  const double wanted = std::clamp(led, 0.8 * o.radius, 1.5 * o.radius);
  double step = std::clamp(wanted - o.sent_radius, -kLargestStepM, kLargestStepM);
  if (std::fabs(step) < kSmallestStepM) step = 0.0;
  if (step == 0.0 && speed < o.sent_speed + kSmallestStepM) return;
  const double radius = o.sent_radius + step;
  char text[160];
  std::snprintf(text, sizeof text,
                "orbit of %.2f m: flown at %.2f m from the autopilot's centre at %.2f m/s, DO_ORBIT radius %.2f m at %.2f m/s",
                o.radius, o.last_flown_m, o.flown_speed, radius, speed);
  hooks_.note(text);
  const uint64_t epoch = epoch_;
  const double before_radius = o.sent_radius, before_speed = o.sent_speed;
  o.correcting = true;
  o.sent_at_s = o.last_report_s;
  o.sent_radius = radius;
  o.sent_speed = speed;
  // Once the orbit ended (cancelled: AUTO.LOITER sent), a resend would put the vehicle back
  // in its Orbit mode.
  auto still_orbiting = [this, epoch] {
    return epoch == epoch_ && orbit_.commanded && vehicle_.custom_mode == autopilot().orbit_mode;
  };
  commands_.send(
      link_.command(ml::cmd::DO_ORBIT, do_orbit_params(radius, speed)),
      [this, epoch, radius, before_radius, before_speed](const CommandResult& result) {
        if (epoch != epoch_ || !orbit_.commanded) return;  // the orbit ended meanwhile
        orbit_.correcting = false;
        if (result.accepted) return;
        // The orbit goes on as PX4 flies it: a refusal of a correction is no failure of the
        // Orbit, but asking again would be refused again.
        orbit_.sent_radius = before_radius, orbit_.sent_speed = before_speed;
        orbit_.corrections_stopped = true;
        char text[96];
        std::snprintf(text, sizeof text, "orbit radius correction to %.2f m not taken: ", radius);
        hooks_.note(text + result.error + "; the orbit goes on without corrections");
      },
      still_orbiting);
}

}  // namespace eamos::mavlink_adapter
