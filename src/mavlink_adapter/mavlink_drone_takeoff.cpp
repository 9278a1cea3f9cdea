// Arming and the takeoff, and the autopilot's auto-disarm around them: ArduPilot
// (DISARM_DELAY) and PX4 (COM_DISARM_PRFLT) disarm a vehicle left armed on the ground, which
// may strike between the mission's Arm and its Takeoff, or while the NAV_TAKEOFF is on its
// way. Such a disarm is survived once per Takeoff by arming again; a second fails it.
#include <cmath>
#include <limits>

#include "mavlink/enums.h"
#include "mavlink_adapter/mavlink_drone.h"

namespace eamos::mavlink_adapter {

namespace ml = eamos::mavlink;
using fleet::Vec3;
using mid::ActionId;
using mid::Outcome;

// The autopilot must hold the fence before the vehicle may fly: Arm waits for the upload,
// and fails with its reason when the vehicle would not take it.
bool MavlinkDrone::arm_needs_fence(ActionId id, const std::function<void()>& armed) {
  if (!fence_wanted_) return false;
  if (!fence_ || !fence_->finished()) {
    after_fence_.push_back([this, id, armed] {
      if (tracker_.running(id)) arm(id, armed);
    });
    return true;
  }
  if (fence_->error().empty()) return false;
  tracker_.fail(id, mid::FailureReason::refused,
                "the autopilot does not hold the mission's fence (geofence upload: true): " + fence_->error(),
                fence_->error());
  return true;
}

void MavlinkDrone::arm(ActionId id, std::function<void()> armed) {
  if (arm_needs_fence(id, armed)) return;
  // Until a HEARTBEAT is folded in, the mode is unknown: switch rather than be refused.
  if (vehicle_.heard && can_arm_in(*link_.autopilot(), vehicle_.custom_mode)) return send_arm(id, std::move(armed));
  auto p = set_mode_params(*link_.autopilot(), link_.autopilot()->arm_mode);
  modes_.send(link_.command(ml::cmd::DO_SET_MODE, {p[0], p[1], p[2]}),
                    [this, id, armed = std::move(armed)](const CommandResult& result) mutable {
                      if (!tracker_.running(id)) return;
                      if (!result.accepted) return end_refused(id, result);
                      send_arm(id, std::move(armed));
                    });
}

// The ARM is sent (again) only while the action that wants it runs: once it has ended (failed,
// cancelled by the failsafe), a resend after a late ACK would arm a vehicle that was left
// down and disarmed.
void MavlinkDrone::send_arm(ActionId id, std::function<void()> armed) {
  disarm_commanded_ = false;
  commands_.send(
      link_.command(ml::cmd::COMPONENT_ARM_DISARM, {1.0f}),
      [this, id, armed = std::move(armed)](const CommandResult& result) {
        if (!tracker_.running(id)) return;
        if (!result.accepted) return end_refused(id, result);
        vehicle_.armed_by_command(true);  // the next HEARTBEAT (20 Hz) confirms it
        publish();
        armed();
      },
      [this, id] { return tracker_.running(id); });
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
    stream_.hold(goal_->target());
    return;
  }
  const Autopilot& ap = *link_.autopilot();
  if (ap.takeoff_altitude_amsl && !vehicle_.have_altitude) {
    // PX4 takes off to an altitude above mean sea level, which GLOBAL_POSITION_INT tells;
    // right after connecting it may not have come yet. Ask again shortly; the action's
    // timeout bounds the wait.
    after_for(id, 0.1, [this, id, altitude] {
      if (motion_owner_ == id && tracker_.running(id)) start_takeoff(id, altitude);
    });
    return;
  }
  const std::array<float, 7> p = takeoff_params(altitude, here);
  if (!ap.takeoff_in_setpoint_mode || vehicle_.custom_mode == ap.setpoint_mode) return send_takeoff(id, altitude, p);
  auto params = set_mode_params(ap, ap.setpoint_mode);
  modes_.send(link_.command(ml::cmd::DO_SET_MODE, {params[0], params[1], params[2]}),
              [this, id, altitude, p](const CommandResult& result) {
                if (!tracker_.running(id)) return;
                if (!result.accepted) return end_refused(id, result);
                send_takeoff(id, altitude, p);
              });
}

std::array<float, 7> MavlinkDrone::takeoff_params(double altitude, Vec3 here) const {
  std::array<float, 7> p{};
  p[3] = NAN;         // yaw: keep the heading it has
  p[4] = p[5] = NAN;  // latitude, longitude: where it stands
  p[6] = static_cast<float>(altitude);
  // PX4: from where the vehicle stands, in the frame the goal is judged in: not from PX4's
  // home (amsl - relative_alt), which PX4 sets where the vehicle stood when it armed and
  // which its EKF puts 0.2-0.3 m off the ground some seconds later (SITL after a landing:
  // a Takeoff(3) hovered at 2.7 m, the edge of the goal's band, and timed out).
  if (link_.autopilot()->takeoff_altitude_amsl) p[6] = static_cast<float>(vehicle_.amsl_m + goal_->target().z - here.z);
  return p;
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
    note(std::string(link_.autopilot()->name) + " refused the takeoff on the ground (" + result.error +
         "): its auto-disarm may have struck as it went out; eamos repeats it, once");
    repeat_takeoff(id, altitude, watch_.heartbeats(), 0.0);
  };
  modes_.send(link_.command(ml::cmd::NAV_TAKEOFF, p), done, current);
}

// Once the vehicle's HEARTBEATs after the refusal show whether it is still armed (the second
// one: the first may have left before the disarm), or after 1.5 s of its time without them:
// start_takeoff arms it again first if it was disarmed.
void MavlinkDrone::repeat_takeoff(ActionId id, double altitude, uint64_t heartbeats_before, double waited_s) {
  constexpr double kStepS = 0.1, kLongestS = 1.5;
  takeoff_repeating_ = id;  // a disarm seen meanwhile is this refusal's (takeoff_disarmed_on_ground)
  if (watch_.heartbeats() >= heartbeats_before + 2 || waited_s >= kLongestS) {
    takeoff_repeating_ = mid::kNoAction;
    return start_takeoff(id, altitude);
  }
  after_for(id, clock_.mission_s(kStepS), [=, this] {
    if (motion_owner_ == id) repeat_takeoff(id, altitude, heartbeats_before, waited_s + kStepS);
  });
}

// A disarm the mission did not ask for. On the ground after the mission's Arm it is the
// autopilot's auto-disarm (ArduPilot DISARM_DELAY, PX4 COM_DISARM_PRFLT): the next Takeoff
// arms again. The mission sees the drone disarmed meanwhile, as it is.
void MavlinkDrone::on_armed_changed() {
  if (vehicle_.armed || disarm_commanded_) return;
  if (takeoff_disarmed_on_ground()) return;
  if (armed_waiting_ && vehicle_.landed())
    note(std::string(link_.autopilot()->name) + " disarmed the vehicle on the ground by itself (auto-disarm); "
         "eamos arms it again before its Takeoff");
  else if (!vehicle_.landed())
    note(std::string(link_.autopilot()->name) + " reports the vehicle disarmed in the air");
}

// The auto-disarm may also strike between our NAV_TAKEOFF and the autopilot's takeoff (it
// counts from arming in the vehicle's clock, which a sped-up SITL keeps a little behind
// ours): the takeoff then never starts. Arm again and send it again, once; a second disarm
// fails the Takeoff rather than fight the autopilot.
bool MavlinkDrone::takeoff_disarmed_on_ground() {
  const mid::ActionRequest* r = tracker_.request(motion_owner_);
  if (!r || r->name != "Takeoff" || !vehicle_.landed() || !tracker_.running(motion_owner_)) return false;
  mid::ActionId id = motion_owner_;
  if (takeoff_repeating_ == id) return true;  // repeat_takeoff arms it again
  if (takeoff_rearmed_ == id) {
    fail_motion(mid::FailureReason::vehicle_fault,
                std::string(link_.autopilot()->name) + " disarmed the vehicle again before it took off" +
                    autopilot_says(tracker_.started_at(id)),
                "disarmed on the ground twice during the takeoff");
    return true;
  }
  takeoff_rearmed_ = id;
  ++takeoff_attempt_;  // the NAV_TAKEOFF out now is not this takeoff's any more (send_takeoff)
  note(std::string(link_.autopilot()->name) + " disarmed the vehicle on the ground during the takeoff (auto-disarm); "
       "eamos arms it again and repeats the takeoff");
  double altitude = r->args[0];
  stream_.hand_over();
  start_takeoff(id, altitude);
  return true;
}

// A failsafe ends with the motors off, as the simulator's does. An autopilot that does not
// disarm by itself after landing (ArduPilot DISARM_DELAY 0, PX4 COM_DISARM_LAND -1), or
// that takes its seconds to, would otherwise leave the vehicle armed on the ground when the
// DEX, which waits for its drone to be safe, ends. Refused (not landed yet, PX4 says), the
// autopilot's own auto-disarm remains, and the DEX waits for it.
void MavlinkDrone::disarm_after_failsafe_landing() {
  if (failsafe_reason_.empty() || !vehicle_.armed || disarm_commanded_) return;
  disarm_commanded_ = true;
  commands_.send(link_.command(ml::cmd::COMPONENT_ARM_DISARM, {0.0f}), nullptr);
}

// A vehicle down and disarmed that the mission did not land (a kill switch, a crash, a GCS)
// cannot fly what it was told: an Orbit or Hover() has no deadline and would run for ever,
// and the mission with it, to its time limit. Land and ReturnHome ended in check_goal just
// now; a Takeoff disarmed on the ground is takeoff_disarmed_on_ground's.
void MavlinkDrone::end_motion_on_the_ground() {
  if (vehicle_.armed || !vehicle_.landed() || motion_owner_ == mid::kNoAction || !tracker_.running(motion_owner_))
    return;
  const mid::ActionRequest* r = tracker_.request(motion_owner_);
  if (!r || r->name == "Takeoff") return;
  stream_.hand_over();
  fail_motion(mid::FailureReason::vehicle_fault,
              std::string(link_.autopilot()->name) + " reports the vehicle on the ground and disarmed while " + r->name +
                  " ran: it cannot go on" + autopilot_says(tracker_.started_at(motion_owner_)),
              "landed and disarmed");
}

}  // namespace eamos::mavlink_adapter
