// The uniform actions in MAVLink terms: what is refused here, what is a command, what is
// flown with setpoints, when each ends and what a deadline allows for. Arming and takeoff
// are in mavlink_drone_takeoff.cpp.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "mavlink/enums.h"
#include "mavlink_adapter/mavlink_drone.h"
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

std::optional<mid::ActionEnd> MavlinkDrone::unavailable() const {
  if (!watch_.lost()) return std::nullopt;
  return mid::ActionEnd{.outcome = Outcome::failed,
                        .reason = "link lost: no HEARTBEAT from system " + std::to_string(link_.sysid()),
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
  if (!uniform.empty() || r.name != "Orbit" || !link_.autopilot()->do_orbit) return uniform;
  return orbit_.radius_refusal(r.args.empty() ? 5.0 : r.args[0]);
}

// Deadlines from the slower of the fleet's and the autopilot's limits (autopilot_params.h);
// a landing descends at the autopilot's landing speed.
double MavlinkDrone::timeout_for(const mid::ActionRequest& r) const {
  fleet::DroneSettings timing = settings_;
  timing.limits = link_.limits().motion;
  if (r.name == "Land" || r.name == "ReturnHome") timing.limits.max_descent_mps = link_.limits().land_mps;
  double timeout = mid::action_timeout(r, reference(), timing);
  // ReturnHome is the autopilot's own return, which climbs and waits before it lands
  // (autopilot_params.h, ReturnProfile); a deadline the fleet file sets is taken as written.
  if (r.name == "ReturnHome" && !settings_.timeouts_s.contains("ReturnHome")) {
    Vec3 from = reference();
    timeout = return_home_duration_s(link_.limits(), from.z - settings_.home.z, horizontal_norm(from - settings_.home)) *
                  mid::kTimeoutMargin +
              mid::kTimeoutSlack_s;
  }
  // A takeoff spools up and ramps its climb before it climbs (autopilot_params.h); a
  // deadline the fleet file sets is taken as written.
  if (r.name == "Takeoff" && !settings_.timeouts_s.contains("Takeoff"))
    timeout += link_.limits().takeoff_delay_s * mid::kTimeoutMargin;
  // Deadlines are the vehicle's time: a SITL that cannot keep up with --speed on a loaded
  // machine flies as fast as ever in its own clock, only its clock runs slow.
  return clock_.mission_s(timeout);
}

void MavlinkDrone::start_system(ActionId id, const mid::ActionRequest& r) {
  if (r.name == "Arm") {
    return arm(id, [this, id] {
      armed_waiting_ = true;
      tracker_.end(id, Outcome::succeeded);
    });
  }
  disarm_commanded_ = true;
  commands_.send(link_.command(ml::cmd::COMPONENT_ARM_DISARM, {0.0f}), [this, id](const CommandResult& result) {
    if (!tracker_.running(id)) return;
    if (!result.accepted) return end_refused(id, result);
    armed_waiting_ = false;
    vehicle_.armed_by_command(false);  // the next HEARTBEAT confirms it
    publish();
    tracker_.end(id, Outcome::succeeded);
  });
}

void MavlinkDrone::start_payload(ActionId id, const mid::ActionRequest& r) {
  if (r.name == "TakePicture") return camera_.take(id);
  int k = fleet::sensor_index(r.name, type_.sensors);
  after_for(id, 0.1, [this, id, k] {
    tracker_.end(id, Outcome::succeeded, "", sensor_value(k));
  });
}

void MavlinkDrone::start_motion(ActionId id, const mid::ActionRequest& r) {
  const Vec3 here = reference();
  motion_start_ = position();
  motion_owner_ = id;
  orbit_.reset();
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
    stream_.hold(*goal);
    return;
  }
  stream_.aim(here);
  if (r.name == "Orbit") return orbit_.start(id, here, r.args.empty() ? 5.0 : r.args[0]);
  stream_.start();  // Hover: hold where it is; Hover(s) ends after s seconds
  if (r.args.size() == 1) {
    after_for(id, r.args[0], [this, id] {
      if (motion_owner_ == id) motion_owner_ = mid::kNoAction;
      tracker_.end(id, Outcome::succeeded);
    });
  }
}

void MavlinkDrone::command_motion(ActionId id, uint16_t cmd, std::array<float, 7> params) {
  modes_.send(link_.command(cmd, params), [this, id](const CommandResult& result) {
    if (!tracker_.running(id)) return;
    if (!result.accepted) return end_refused(id, result);
    autopilot_flies_it();
  });
}

void MavlinkDrone::autopilot_flies_it() {
  // Its own mode now: the setpoints stop only once it took the command, so a refused one
  // leaves the vehicle doing what it did.
  stream_.hand_over();
  check_goal();
}

void MavlinkDrone::end_refused(ActionId id, const CommandResult& result) {
  if (motion_owner_ == id) {
    motion_owner_ = mid::kNoAction;
    goal_.reset();
  }
  std::string reason = std::string("refused by ") + link_.autopilot()->name + ": " + result.error;
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

void MavlinkDrone::stop_action(ActionId id) {
  clear_action_timer(id);  // also called for a failsafe, where the base has not cleared it
  camera_.forget(id);
  if (id != motion_owner_) return;
  motion_owner_ = mid::kNoAction;
  goal_.reset();
  holding_.reset();
  orbit_.stop();
  hold_here();
}

void MavlinkDrone::check_goal() {
  if (motion_owner_ == mid::kNoAction || !tracker_.running(motion_owner_)) return;
  bool done = false;
  if (until_ == Until::reached)
    done = goal_ && vehicle_.have_position && goal_->reached(position()) &&
           vehicle_.settling_speed() <= settings_.tolerance.settled_mps;
  if (until_ == Until::landed) done = vehicle_.landed();
  if (!done) return;
  ActionId id = motion_owner_;
  motion_owner_ = mid::kNoAction;
  Vec3 goal_target = goal_ ? goal_->target() : position();
  goal_.reset();
  tracker_.end(id, Outcome::succeeded);
  if (until_ != Until::reached) return;
  // Hold the goal with setpoints, also after a Takeoff the autopilot flew in its own mode:
  // PX4 needs the stream before OFFBOARD, and an already running stream lets the next
  // FlyTo start at once instead of half a second later.
  holding_ = goal_target;
  stream_.hold(goal_target);
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

// The same goals as distance_left(): a Takeoff the autopilot flies in its own mode has none
// until it hands over (the vehicle climbs straight up, which separation sees from its samples).
std::optional<Vec3> MavlinkDrone::goal_of(ActionId id) const {
  const mid::ActionRequest* r = tracker_.request(id);
  if (id != motion_owner_ || !r || !vehicle_.have_position) return std::nullopt;
  if (goal_) return goal_->target();
  const Vec3 here = position();
  if (r->name == "Land") return Vec3{here.x, here.y, ground_z()};
  if (r->name == "ReturnHome") return Vec3{settings_.home.x, settings_.home.y, ground_z()};
  return std::nullopt;
}

// In the vehicle's time, like the deadline itself (timeout_for); a deadline the fleet file
// sets never moves on.
double MavlinkDrone::closing_window_s(const mid::ActionRequest& r) const {
  if (settings_.timeouts_s.contains(r.name)) return 0.0;
  return clock_.mission_s(mid::kClosingWindow_s);
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
    stream_.stop();
    return;
  }
  stream_.hold(position());
}

void MavlinkDrone::fail_all(mid::FailureReason why, const std::string& reason) {
  end_all({.outcome = Outcome::failed, .reason = reason, .failure = why});
  camera_.forget_all();
  motion_owner_ = mid::kNoAction;
  goal_.reset();
  orbit_.reset();
}

void MavlinkDrone::failsafe(fleet::Failsafe what) {
  refuse_from_now(std::string("failsafe: ") + fleet::failsafe_name(what));
  for (ActionId id : tracker_.running_ids()) stop_action(id);
  end_all({Outcome::cancelled, failsafe_reason_});
  if (vehicle_.landed()) {
    stream_.stop();
    armed_waiting_ = false;
    disarm_commanded_ = true;
    if (vehicle_.armed) commands_.send(link_.command(ml::cmd::COMPONENT_ARM_DISARM, {0.0f}), nullptr);
    return;
  }
  if (what == fleet::Failsafe::hover) return hold_here();
  ml::CommandLong c = what == fleet::Failsafe::land ? link_.command(ml::cmd::NAV_LAND, kLandHere)
                                                     : link_.command(ml::cmd::NAV_RETURN_TO_LAUNCH);
  modes_.send(c, [this](const CommandResult& result) {
    if (result.accepted) stream_.hand_over();  // refused: keep holding where it is
  });
}

void MavlinkDrone::fail_motion(mid::FailureReason why, const std::string& reason, const std::string& detail) {
  if (motion_owner_ == mid::kNoAction) return;
  ActionId id = motion_owner_;
  motion_owner_ = mid::kNoAction;
  goal_.reset();
  orbit_.reset();
  tracker_.fail(id, why, reason, detail);
}

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

}  // namespace eamos::mavlink_adapter
