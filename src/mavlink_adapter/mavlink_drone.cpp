// The uniform actions in MAVLink terms: what is refused here, what is a command, what is
// flown with setpoints. Telemetry, the link and the setpoint stream are in
// mavlink_drone_link.cpp.
#include "mavlink_adapter/mavlink_drone.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "diag/log.h"
#include "mavlink/enums.h"
#include "mid/requests.h"
#include "mid/timeouts.h"
#include "mid/vec.h"

namespace eamos::mavlink_adapter {

namespace ml = eamos::mavlink;
using fleet::Vec3;
using mid::ActionId;
using mid::Outcome;

namespace {

/// MAV_CMD_NAV_LAND where the vehicle is: yaw NaN keeps the heading; latitude and longitude 0
/// mean "here" to both autopilots.
constexpr std::array<float, 7> kLandHere{0, 0, 0, NAN, 0, 0, 0};

}  // namespace

using mid::metres;

MavlinkDrone::MavlinkDrone(fleet::DroneSettings settings, fleet::DroneType type,
                           mid::EventLoop& loop, MavlinkOptions options)
    : AdapterDrone(loop, std::move(type)),
      settings_(std::move(settings)),
      options_(options),
      commands_(loop, [this](const ml::Message& m) { send(m); }, options.commands) {}

MavlinkDrone::~MavlinkDrone() {
  if (link_ && link_->foreign_datagrams() > 0)
    diag::Logger{"mavlink", settings_.name}.warning(std::to_string(link_->foreign_datagrams()) +
                                                    " datagram(s) from other addresses than the vehicle's were ignored in all");
  link_.reset();  // joins the receive thread: nothing new gets posted
  for (mid::TimerId t : {stream_timer_, heartbeat_timer_, watchdog_timer_, heartbeat_poll_timer_}) loop_.cancel(t);
}

// --- starting actions ----------------------------------------------------------------------

std::optional<mid::ActionEnd> MavlinkDrone::unavailable() const {
  if (!link_lost_) return std::nullopt;
  return mid::ActionEnd{.outcome = Outcome::failed,
                        .reason = "link lost: no HEARTBEAT from system " + std::to_string(sysid_),
                        .failure = mid::FailureReason::link_lost};
}

std::string MavlinkDrone::refusal(const mid::ActionRequest& r, const fleet::ActionSpec& spec) const {
  // The uniform rules, checked here so every autopilot keeps them alike; what only the
  // autopilot knows (arming checks, its own limits) it judges, and its MAV_RESULT becomes the
  // reason. Takeoff while disarmed is refused here too: PX4 may accept the takeoff mode while
  // disarmed and take off by itself once something arms it later.
  // A vehicle the autopilot disarmed while it waited for its Takeoff is armed again by it.
  bool armed = vehicle_.armed || (r.name == "Takeoff" && armed_waiting_ && vehicle_.landed());
  mid::VehicleFacts v{armed, vehicle_.landed(), reference(), ""};
  if (tracker_.motion() != mid::kNoAction) v.running_motion = tracker_.request(tracker_.motion())->name;
  if (r.name == "Disarm") v.position = position();
  std::string uniform = mid::uniform_refusal(r, spec, v, settings_);
  if (!uniform.empty() || r.name != "Orbit" || !autopilot_->do_orbit) return uniform;
  return orbit_radius_refusal(r.args.empty() ? 5.0 : r.args[0]);
}

// PX4 orbits from 1 m to MC_ORBIT_RAD_MAX. The vehicle first flies out to the circle
// (start_orbit), so a radius PX4 would refuse is refused before it moves, not at the circle.
std::string MavlinkDrone::orbit_radius_refusal(double radius) const {
  char text[160];
  if (radius < 1.0) {
    std::snprintf(text, sizeof text, "orbit radius %.1f m is below the smallest %s flies (1 m)", radius,
                  autopilot_->name);
    return text;
  }
  const double largest = limits_.orbit_radius_max_m;
  if (largest <= 0.0 || radius <= largest) return "";
  std::snprintf(text, sizeof text, "orbit radius %.1f m is above %s's MC_ORBIT_RAD_MAX %.0f m", radius,
                autopilot_->name, largest);
  return text;
}

// Deadlines from the slower of the fleet's and the autopilot's limits (autopilot_params.h);
// a landing descends at the autopilot's landing speed.
double MavlinkDrone::timeout_for(const mid::ActionRequest& r) const {
  fleet::DroneSettings timing = settings_;
  timing.limits = limits_.motion;
  if (r.name == "Land" || r.name == "ReturnHome") timing.limits.max_descent_mps = limits_.land_mps;
  double timeout = mid::action_timeout(r, reference(), timing);
  // ReturnHome is the autopilot's own return, which climbs and waits before it lands
  // (autopilot_params.h, ReturnProfile); a deadline the fleet file sets is taken as written.
  if (r.name == "ReturnHome" && !settings_.timeouts_s.contains("ReturnHome")) {
    Vec3 from = reference();
    timeout = return_home_duration_s(limits_, from.z - settings_.home.z, horizontal_norm(from - settings_.home)) *
                  mid::kTimeoutMargin +
              mid::kTimeoutSlack_s;
  }
  // A takeoff spools up and ramps its climb before it climbs (autopilot_params.h); a
  // deadline the fleet file sets is taken as written.
  if (r.name == "Takeoff" && !settings_.timeouts_s.contains("Takeoff"))
    timeout += limits_.takeoff_delay_s * mid::kTimeoutMargin;
  // Deadlines are the vehicle's time: a SITL that cannot keep up with --speed on a loaded
  // machine flies as fast as ever in its own clock, only its clock runs slow.
  return mission_s(timeout);
}

void MavlinkDrone::start_system(ActionId id, const mid::ActionRequest& r) {
  if (r.name == "Arm") {
    return arm(id, [this, id] {
      armed_waiting_ = true;
      tracker_.end(id, Outcome::succeeded);
    });
  }
  disarm_commanded_ = true;
  commands_.send(command(ml::cmd::COMPONENT_ARM_DISARM, {0.0f}), [this, id](const CommandResult& result) {
    if (!tracker_.running(id)) return;
    if (!result.accepted) return end_refused(id, result);
    armed_waiting_ = false;
    vehicle_.armed = false;  // the next HEARTBEAT confirms it
    publish();
    tracker_.end(id, Outcome::succeeded);
  });
}

void MavlinkDrone::arm(ActionId id, std::function<void()> armed) {
  // Until a HEARTBEAT is folded in, the mode is unknown: switch rather than be refused.
  if (vehicle_.heard && can_arm_in(*autopilot_, vehicle_.custom_mode)) return send_arm(id, std::move(armed));
  auto p = set_mode_params(*autopilot_, autopilot_->arm_mode);
  send_mode_command(command(ml::cmd::DO_SET_MODE, {p[0], p[1], p[2]}),
                    [this, id, armed = std::move(armed)](const CommandResult& result) mutable {
                      if (!tracker_.running(id)) return;
                      if (!result.accepted) return end_refused(id, result);
                      send_arm(id, std::move(armed));
                    });
}

void MavlinkDrone::send_arm(ActionId id, std::function<void()> armed) {
  disarm_commanded_ = false;
  commands_.send(command(ml::cmd::COMPONENT_ARM_DISARM, {1.0f}),
                 [this, id, armed = std::move(armed)](const CommandResult& result) {
                   if (!tracker_.running(id)) return;
                   if (!result.accepted) return end_refused(id, result);
                   vehicle_.armed = true;  // the next HEARTBEAT (20 Hz) confirms it
                   publish();
                   armed();
                 });
}

void MavlinkDrone::start_payload(ActionId id, const mid::ActionRequest& r) {
  if (r.name == "TakePicture") return take_picture(id);
  int k = fleet::sensor_index(r.name, type_.sensors);
  after_for(id, 0.1, [this, id, k] {
    tracker_.end(id, Outcome::succeeded, "", sensor_value(k));
  });
}

void MavlinkDrone::take_picture(ActionId id) {
  std::array<float, 7> p{};
  if (autopilot_->picture_command == ml::cmd::DO_DIGICAM_CONTROL) p[4] = 1;  // param5: shoot once
  else p[2] = 1;                                                             // param3: one image
  pictures_pending_[id] = {};
  commands_.send(command(autopilot_->picture_command, p), [this, id](const CommandResult& result) {
    auto it = pictures_pending_.find(id);
    if (!tracker_.running(id) || it == pictures_pending_.end()) return;
    if (!result.accepted) {
      pictures_pending_.erase(it);
      auto why = result.answered ? mid::FailureReason::refused : mid::FailureReason::timed_out;
      tracker_.fail(id, why, "no picture: " + result.error, result.error);
      return;
    }
    it->second.acked = true;
    if (it->second.confirmed) return end_picture(id);  // the camera spoke before the ACK
    after_for(id, options_.picture_confirm_s, [this, id] {
      pictures_pending_.erase(id);
      char text[256];
      std::snprintf(text, sizeof text,
                    "no picture: %s accepted %s but no camera confirmed a picture (CAMERA_TRIGGER, "
                    "CAMERA_FEEDBACK or CAMERA_IMAGE_CAPTURED) within %.1f s; is a camera configured "
                    "(ArduPilot CAM1_TYPE, PX4 TRIG_MODE and TRIG_INTERFACE)?",
                    autopilot_->name, ml::command_name(autopilot_->picture_command).c_str(),
                    options_.picture_confirm_s);
      if (tracker_.running(id)) tracker_.fail(id, mid::FailureReason::timed_out, text);
    });
  });
}

// The oldest picture still waiting for its camera gets this confirmation; one nobody waits
// for (a ground station's, a survey's trigger) is only noted.
void MavlinkDrone::on_camera_capture(const ml::CameraCapture& c) {
  auto it = std::find_if(pictures_pending_.begin(), pictures_pending_.end(),
                         [](const auto& p) { return !p.second.confirmed; });
  const char* what = c.message_id == ml::msg::CAMERA_TRIGGER    ? "CAMERA_TRIGGER"
                     : c.message_id == ml::msg::CAMERA_FEEDBACK ? "CAMERA_FEEDBACK"
                                                                : "CAMERA_IMAGE_CAPTURED";
  note(std::string(autopilot_->name) + " camera: " + (c.captured ? "took" : "failed to take") + " image " +
       std::to_string(c.image_index) + " (" + what + ")");
  // PX4 reports one image twice (CAMERA_TRIGGER, then CAMERA_IMAGE_CAPTURED, same number):
  // the second must not confirm the next picture before its camera has taken it.
  if (last_image_index_ == c.image_index) return;
  if (it == pictures_pending_.end()) return;
  last_image_index_ = c.image_index;
  ActionId id = it->first;
  if (!c.captured) {
    clear_action_timer(id);
    pictures_pending_.erase(it);
    tracker_.fail(id, mid::FailureReason::vehicle_fault,
                  std::string("no picture: the camera reported a failed capture (") + what + ")", what);
    return;
  }
  it->second.confirmed = true;
  if (it->second.acked) end_picture(id);
}

void MavlinkDrone::end_picture(ActionId id) {
  clear_action_timer(id);
  pictures_pending_.erase(id);
  ++pictures_;
  publish();
  tracker_.end(id, Outcome::succeeded);
}

void MavlinkDrone::start_motion(ActionId id, const mid::ActionRequest& r) {
  const Vec3 here = reference();
  motion_start_ = position();
  motion_owner_ = id;
  orbit_ = {};
  goal_.reset();
  holding_.reset();
  until_ = Until::forever;
  if (r.name == "Takeoff") return start_takeoff(id, r.args[0]);
  if (r.name == "Land" || r.name == "ReturnHome") {
    if (r.name == "Land" && vehicle_.landed()) {
      motion_owner_ = mid::kNoAction;
      tracker_.end(id, Outcome::succeeded);
      return;
    }
    until_ = Until::landed;
    if (r.name == "ReturnHome") return command_motion(id, ml::cmd::NAV_RETURN_TO_LAUNCH);
    return command_motion(id, ml::cmd::NAV_LAND, kLandHere);
  }
  if (auto goal = mid::goal_position(r, here, settings_.home)) {
    goal_.emplace(*goal, settings_.tolerance);
    until_ = Until::reached;
    setpoint_ = *goal;
    stream_setpoints();
    return;
  }
  setpoint_ = here;
  if (r.name == "Orbit") return start_orbit(here, r.args.empty() ? 5.0 : r.args[0]);
  stream_setpoints();  // Hover: hold where it is; Hover(s) ends after s seconds
  if (r.args.size() == 1) {
    after_for(id, r.args[0], [this, id] {
      if (motion_owner_ == id) motion_owner_ = mid::kNoAction;
      tracker_.end(id, Outcome::succeeded);
    });
  }
}

void MavlinkDrone::start_takeoff(ActionId id, double altitude) {
  if (!vehicle_.armed && vehicle_.landed()) {
    // The autopilot disarmed it while it waited (refusal() let only that case through).
    note("arming again for " + tracker_.request(id)->name + " after the autopilot's auto-disarm");
    return arm(id, [this, id, altitude] {
      if (motion_owner_ == id) start_takeoff(id, altitude);
    });
  }
  armed_waiting_ = false;
  const Vec3 here = position();
  // A Takeoff asks for a height: done once settled at it, wherever across the autopilot's own
  // climb and hover put the vehicle. PX4 SITL's hover after its takeoff wanders up to 1 m (its
  // estimate moving); judged over where it began, a Takeoff would wait seconds for the wander
  // to come back, and everything the mission starts after it would start that much later. The
  // hold after every goal brings the vehicle back over its start.
  fleet::GoalTolerance height_only = settings_.tolerance;
  height_only.horizontal_m = std::numeric_limits<double>::infinity();
  goal_.emplace(Vec3{here.x, here.y, ground_z() + altitude}, height_only);
  until_ = Until::reached;
  if (!vehicle_.landed()) {
    // Already up: autopilots refuse NAV_TAKEOFF in the air, the simulator climbs or descends
    // to the altitude; do what the simulator does, with a setpoint.
    setpoint_ = goal_->target();
    stream_setpoints();
    return;
  }
  std::array<float, 7> p{};
  p[3] = NAN;         // yaw: keep the heading it has
  p[4] = p[5] = NAN;  // latitude, longitude: where it stands
  p[6] = static_cast<float>(altitude);
  if (autopilot_->takeoff_altitude_amsl) {
    if (!vehicle_.have_altitude) {
      // PX4 takes off to an altitude above mean sea level, which GLOBAL_POSITION_INT tells;
      // right after connecting it may not have come yet. Ask again shortly; the action's
      // timeout bounds the wait.
      after_for(id, 0.1, [this, id, altitude] {
        if (motion_owner_ == id && tracker_.running(id)) start_takeoff(id, altitude);
      });
      return;
    }
    // From where the vehicle stands, in the frame the goal is judged in: not from PX4's
    // home (amsl - relative_alt), which PX4 sets where the vehicle stood when it armed and
    // which its EKF puts 0.2-0.3 m off the ground some seconds later (SITL after a landing:
    // a Takeoff(3) hovered at 2.7 m, the edge of the goal's band, and timed out).
    p[6] = static_cast<float>(vehicle_.amsl_m + goal_->target().z - here.z);
  }
  if (!autopilot_->takeoff_in_setpoint_mode || vehicle_.custom_mode == autopilot_->setpoint_mode)
    return send_takeoff(id, altitude, p);
  auto params = set_mode_params(*autopilot_, autopilot_->setpoint_mode);
  send_mode_command(command(ml::cmd::DO_SET_MODE, {params[0], params[1], params[2]}),
                    [this, id, altitude, p](const CommandResult& result) {
                   if (!tracker_.running(id)) return;
                   if (!result.accepted) return end_refused(id, result);
                   send_takeoff(id, altitude, p);
                 });
}

// One attempt of NAV_TAKEOFF. The auto-disarm can strike as it goes out: ArduCopter SITL's
// DISARM_DELAY ran out 40 ms before Listing 2's Takeoff, while eamos' last HEARTBEAT still
// said armed, and the takeoff was answered MAV_RESULT_FAILED. So a takeoff refused on the
// ground is repeated, armed again first if the vehicle is disarmed by then, once for the
// Takeoff (takeoff_disarmed_on_ground is the same repeat when a HEARTBEAT shows the disarm
// first); refused again, it fails with the autopilot's answer. The answer to an attempt a
// later one replaced is not this takeoff's, and such an attempt is not sent again.
void MavlinkDrone::send_takeoff(ActionId id, double altitude, std::array<float, 7> p) {
  const uint32_t attempt = ++takeoff_attempt_;
  auto current = [this, id, attempt] { return attempt == takeoff_attempt_ && motion_owner_ == id; };
  auto done = [this, id, altitude, attempt](const CommandResult& result) {
    if (attempt != takeoff_attempt_ || !tracker_.running(id)) return;
    if (result.accepted) return autopilot_flies_it();
    if (!result.answered || !vehicle_.landed() || takeoff_rearmed_ == id) return end_refused(id, result);
    takeoff_rearmed_ = id;
    note(std::string(autopilot_->name) + " refused the takeoff on the ground (" + result.error +
         "): its auto-disarm may have struck as it went out; eamos repeats it, once");
    repeat_takeoff(id, altitude, heartbeats_, 0.0);
  };
  send_mode_command(command(ml::cmd::NAV_TAKEOFF, p), done, current);
}

// Once the vehicle's HEARTBEATs after the refusal show whether it is still armed (the second
// one: the first may have left before the disarm), or after 1.5 s of its time without them:
// start_takeoff arms it again first if it was disarmed.
void MavlinkDrone::repeat_takeoff(ActionId id, double altitude, uint64_t heartbeats_before, double waited_s) {
  constexpr double kStepS = 0.1, kLongestS = 1.5;
  takeoff_repeating_ = id;  // a disarm seen meanwhile is this refusal's (takeoff_disarmed_on_ground)
  if (heartbeats_ >= heartbeats_before + 2 || waited_s >= kLongestS) {
    takeoff_repeating_ = mid::kNoAction;
    return start_takeoff(id, altitude);
  }
  after_for(id, mission_s(kStepS), [=, this] {
    if (motion_owner_ == id) repeat_takeoff(id, altitude, heartbeats_before, waited_s + kStepS);
  });
}

void MavlinkDrone::command_motion(ActionId id, uint16_t cmd, std::array<float, 7> params) {
  send_mode_command(command(cmd, params), [this, id](const CommandResult& result) {
    if (!tracker_.running(id)) return;
    if (!result.accepted) return end_refused(id, result);
    autopilot_flies_it();
  });
}

void MavlinkDrone::autopilot_flies_it() {
  // Its own mode now: the setpoints stop only once it took the command, so a refused one
  // leaves the vehicle doing what it did.
  streaming_ = false;
  in_control_ = false;
  check_goal();
}

void MavlinkDrone::end_refused(ActionId id, const CommandResult& result) {
  if (motion_owner_ == id) {
    motion_owner_ = mid::kNoAction;
    goal_.reset();
  }
  std::string reason = std::string("refused by ") + autopilot_->name + ": " + result.error;
  if (!result.answered) {
    // No COMMAND_ACK after every retry: the autopilot never said no, it said nothing.
    tracker_.fail(id, mid::FailureReason::timed_out, reason, result.error);
    return;
  }
  // The autopilot's reason ("Arm: LAND mode not armable") comes as STATUSTEXT, which
  // ArduPilot queues and sends after the COMMAND_ACK: wait a moment for it.
  double since = tracker_.started_at(id);
  after_for(id, options_.statustext_wait_s, [this, id, reason, since, error = result.error] {
    std::string says = autopilot_says(since);
    tracker_.fail(id, mid::FailureReason::refused, reason + says, error + says);
  });
}

// --- stopping ------------------------------------------------------------------------------

void MavlinkDrone::stop_action(ActionId id) {
  clear_action_timer(id);  // also called for a failsafe, where the base has not cleared it
  pictures_pending_.erase(id);
  if (id != motion_owner_) return;
  motion_owner_ = mid::kNoAction;
  goal_.reset();
  holding_.reset();
  bool autopilot_orbits = orbit_.commanded;
  orbit_ = {};
  if (autopilot_orbits) leave_orbit();
  hold_here();
}

// How far the vehicle still has to go, for a deadline that comes while it closes in (PX4 SIH
// was seen creeping the last 0.3-0.6 m to a setpoint for seconds): to its goal; down to the
// ground for Land; to the ground at home for ReturnHome.
double MavlinkDrone::distance_left(ActionId id) const {
  const mid::ActionRequest* r = tracker_.request(id);
  if (id != motion_owner_ || !r || !vehicle_.have_position) return std::numeric_limits<double>::quiet_NaN();
  const Vec3 here = position();
  if (goal_) return norm(here - goal_->target());
  if (r->name == "Land") return std::max(0.0, here.z - ground_z());
  if (r->name == "ReturnHome") return norm(here - Vec3{settings_.home.x, settings_.home.y, ground_z()});
  return std::numeric_limits<double>::quiet_NaN();
}

// In the vehicle's time, like the deadline itself (timeout_for); a deadline the fleet file
// sets never moves on.
double MavlinkDrone::closing_window_s(const mid::ActionRequest& r) const {
  if (settings_.timeouts_s.contains(r.name)) return 0.0;
  return mission_s(mid::kClosingWindow_s);
}

std::string MavlinkDrone::timeout_detail(ActionId id) const {
  // A goal missed is seldom missed by much: say by how much, against the type's tolerance,
  // so the fleet file's `tolerance:` can be judged from the failure alone.
  if (id != motion_owner_ || !goal_ || !vehicle_.have_position) return "";
  const Vec3 off = position() - goal_->target();
  const fleet::GoalTolerance& t = settings_.tolerance;
  char text[256];
  std::snprintf(text, sizeof text,
                "%.2f m across, %.2f m %s its goal, at %.2f m/s (the estimator says %.2f m/s); the type's "
                "tolerance: %.2f m, %.2f m, %.2f m/s",
                horizontal_norm(off), std::fabs(off.z), off.z < 0 ? "below" : "above", vehicle_.settling_speed(),
                norm(vehicle_.ned_velocity), t.horizontal_m, t.vertical_m, t.settled_mps);
  return text;
}

void MavlinkDrone::hold_here() {
  if (vehicle_.landed() || !vehicle_.armed) {
    streaming_ = false;
    return;
  }
  setpoint_ = position();
  stream_setpoints();
}

void MavlinkDrone::fail_all(mid::FailureReason why, const std::string& reason) {
  end_all({.outcome = Outcome::failed, .reason = reason, .failure = why});
  pictures_pending_.clear();
  motion_owner_ = mid::kNoAction;
  goal_.reset();
  orbit_ = {};
}

void MavlinkDrone::failsafe(fleet::Failsafe what) {
  refuse_from_now(std::string("failsafe: ") + fleet::failsafe_name(what));
  for (ActionId id : tracker_.running_ids()) stop_action(id);
  end_all({Outcome::cancelled, failsafe_reason_});
  if (vehicle_.landed()) {
    streaming_ = false;
    armed_waiting_ = false;
    disarm_commanded_ = true;
    if (vehicle_.armed) commands_.send(command(ml::cmd::COMPONENT_ARM_DISARM, {0.0f}), nullptr);
    return;
  }
  if (what == fleet::Failsafe::hover) return hold_here();
  ml::CommandLong c = what == fleet::Failsafe::land ? command(ml::cmd::NAV_LAND, kLandHere)
                                                     : command(ml::cmd::NAV_RETURN_TO_LAUNCH);
  send_mode_command(c, [this](const CommandResult& result) {
    if (!result.accepted) return;  // refused: keep holding where it is
    streaming_ = false;
    in_control_ = false;
  });
}

// --- properties ----------------------------------------------------------------------------

double MavlinkDrone::remaining(Vec3 from) const {
  if (goal_) return norm(goal_->target() - from);
  // Land and ReturnHome: what is left is the way home (ReturnHome only) and the way down.
  double across = 0.0;
  const mid::ActionRequest* r = tracker_.request(motion_owner_);
  if (r && r->name == "ReturnHome") across = horizontal_norm(from - settings_.home);
  return across + std::max(0.0, from.z - ground_z());
}

std::optional<double> MavlinkDrone::progress(ActionId id) const {
  const mid::ActionRequest* r = tracker_.request(id);
  if (!r || mid::is_endless(*r)) return std::nullopt;
  double fraction = 0.0;
  if (id == motion_owner_ && until_ != Until::forever) {
    double total = remaining(motion_start_);
    fraction = total > 0.0 ? 1.0 - remaining(position()) / total : 1.0;
  } else if (r->name == "Hover") {
    double elapsed = loop_.now() - tracker_.started_at(id);
    fraction = r->args[0] > 0.0 ? elapsed / r->args[0] : 1.0;
  }
  return std::clamp(fraction, 0.0, 1.0);
}

Vec3 MavlinkDrone::reference() const {
  if (holding_ && mid::LocationValidator(*holding_, settings_.tolerance).reached(position()))
    return *holding_;
  return position();
}

Vec3 MavlinkDrone::position() const {
  return vehicle_.have_position ? ned_to_mission(vehicle_.ned, settings_.home) : settings_.home;
}

double MavlinkDrone::sensor_value(int k) const {
  auto it = settings_.sensors.find("Sensor" + std::to_string(k));
  if (it == settings_.sensors.end()) return 0.0;
  return it->second.base + dot(it->second.gradient, position());
}

mid::DroneState MavlinkDrone::state() const {
  mid::DroneState s;
  s.t = loop_.now();
  Vec3 p = position();
  s.x = p.x;
  s.y = p.y;
  s.z = p.z;
  s.battery = vehicle_.battery >= 0 ? vehicle_.battery : settings_.battery_percent;
  s.armed = vehicle_.armed;
  s.landed = vehicle_.landed();
  for (int k = 1; k <= type_.sensors; ++k) s.sensors["Sensor" + std::to_string(k)] = sensor_value(k);
  s.pictures = pictures_;
  if (vehicle_.heading_deg >= 0) s.heading = vehicle_.heading_deg;
  if (autopilot_ && vehicle_.heard) s.mode = mode_name(*autopilot_, vehicle_.custom_mode);
  s.link_lost = link_lost_;
  return s;
}

mid::SubscriptionId MavlinkDrone::subscribe(mid::StateCallback fn) {
  return broker_.subscribe(std::move(fn));
}

void MavlinkDrone::publish() {
  if (!broker_.empty()) broker_.publish(state());
}

}  // namespace eamos::mavlink_adapter
