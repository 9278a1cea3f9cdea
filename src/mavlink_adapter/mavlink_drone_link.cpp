// The MavlinkDrone's side of the wire: connecting, frames from the link, heartbeats both
// ways, link loss, telemetry requests, goal checks and the setpoint stream.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <map>
#include <mutex>

#include "diag/log.h"
#include "mavlink/enums.h"
#include "mavlink_adapter/mavlink_drone.h"
#include "mid/vec.h"

namespace eamos::mavlink_adapter {

namespace ml = eamos::mavlink;
using fleet::Vec3;
using mid::ActionId;
using mid::Outcome;

/// The first autopilot HEARTBEAT and the parameters read at connect, handed from the link's
/// thread to connect().
struct FirstHeartbeat {
  std::mutex mutex;
  std::condition_variable cv;
  bool heard = false;
  bool signed_heard = false;  ///< a HEARTBEAT with a verified signature came
  uint8_t sysid = 0;
  uint8_t autopilot = 0;
  std::map<std::string, float> params;  ///< PARAM_VALUE of the autopilot, by name
};

namespace {

constexpr uint8_t kLastMavResult = 9;  ///< MAV_RESULT_UNSUPPORTED_MAV_FRAME

/// Reads `params` by name, asking again every half second for those missing, for at most
/// `timeout_s` wall seconds; blocking like the wait for the HEARTBEAT (`lock` holds
/// `first`'s mutex). What did not come is missing from the result.
std::map<std::string, float> read_params(FirstHeartbeat& first, std::unique_lock<std::mutex>& lock,
                                         const std::vector<LimitParam>& params, double timeout_s,
                                         const std::function<void(const char*)>& request) {
  auto all_read = [&] {
    for (const LimitParam& p : params)
      if (!first.params.contains(p.name)) return false;
    return true;
  };
  using clock = std::chrono::steady_clock;
  auto deadline = clock::now() + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(timeout_s));
  while (!all_read() && clock::now() < deadline) {
    std::vector<const char*> missing;
    for (const LimitParam& p : params)
      if (!first.params.contains(p.name)) missing.push_back(p.name);
    lock.unlock();  // the link's thread fills `first` meanwhile
    for (const char* name : missing) request(name);
    lock.lock();
    first.cv.wait_until(lock, std::min(deadline, clock::now() + std::chrono::milliseconds(500)), all_read);
  }
  return first.params;
}

constexpr std::size_t kTextsKept = 32;
constexpr std::size_t kMaxTextLength = 50 * 8;  ///< longest text assembled from chunks
constexpr std::size_t kMaxChunkedTexts = 4;     ///< texts being assembled at once
constexpr uint8_t kSeverityWarning = 4;  ///< MAV_SEVERITY_WARNING: refusals explain at or above it

const char* severity_name(uint8_t s) {
  static const char* names[] = {"emergency", "alert", "critical", "error", "warning", "notice", "info", "debug"};
  return s < 8 ? names[s] : "unknown";
}

}  // namespace

/// The link id of our signed frames: one link per drone, so any fixed value serves.
constexpr uint8_t kSigningLinkId = 1;

// setup: true: SETUP_SIGNING to the vehicle (again every half second) until its first signed
// HEARTBEAT, then unsigned frames are dropped. Sent unsigned: a vehicle without a key drops
// signed frames it cannot check (ours does; ArduPilot would take them), and one with another
// key must refuse it anyway. Without setup the vehicle has signed from its first frame (the
// link required it), and there is nothing to do.
std::string MavlinkDrone::give_key(FirstHeartbeat& first, std::unique_lock<std::mutex>& lock,
                                   const ml::SigningKey& key) {
  if (!settings_.signing_setup) return "";
  ml::SetupSigning setup{sysid_, ml::comp::AUTOPILOT1, key.bytes, ml::signing_time_now()};
  auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(options_.connect_timeout_s);
  while (!first.signed_heard && std::chrono::steady_clock::now() < until) {
    send(ml::pack(setup));
    first.cv.wait_for(lock, std::chrono::milliseconds(500), [&] { return first.signed_heard; });
  }
  if (!first.signed_heard)
    return "system " + std::to_string(sysid_) + " did not sign its frames after SETUP_SIGNING within " +
           std::to_string(static_cast<int>(options_.connect_timeout_s)) +
           " s; does its autopilot support MAVLink 2 signing (ArduPilot does; PX4 needs MAV_SIGN_CFG)?";
  link_->require_signed(true);
  diag::Logger{"mavlink", settings_.name}.info("system " + std::to_string(sysid_) +
                                               " took the signing key; unsigned frames are dropped from now on");
  return "";
}

std::string MavlinkDrone::connect(const ml::Endpoint& endpoint) {
  auto first = std::make_shared<FirstHeartbeat>();
  const uint8_t wanted = static_cast<uint8_t>(settings_.sysid);
  std::weak_ptr<bool> alive = alive_;
  mid::EventLoop* loop = &loop_;
  // Runs on the link's thread: it may only note the first heartbeat and post the frame.
  auto handler = [this, first, wanted, alive, loop](ml::Frame frame) {
    if (auto pv = ml::unpack_param_value(frame.message); pv && frame.compid == ml::comp::AUTOPILOT1) {
      std::lock_guard lock(first->mutex);
      if (first->heard && frame.sysid == first->sysid) first->params[pv->param_id] = pv->param_value;
      first->cv.notify_all();
      return;
    }
    if (auto hb = ml::unpack_heartbeat(frame.message);
        hb && hb->autopilot != ml::autopilot::INVALID && (wanted == 0 || frame.sysid == wanted)) {
      std::lock_guard lock(first->mutex);
      if (!first->heard) {
        first->heard = true;
        first->sysid = frame.sysid;
        first->autopilot = hb->autopilot;
      }
      if (frame.sysid == first->sysid && frame.signature_verified) first->signed_heard = true;
      first->cv.notify_all();
    }
    loop->post([this, alive, frame = std::move(frame)] {
      if (alive.lock()) this->on_frame(frame);
    });
  };
  std::optional<ml::SigningKey> key;
  if (!settings_.signing_key.empty()) {
    std::string error;
    key = ml::parse_signing_key(settings_.signing_key, error);
    if (!key) return "signing key of " + settings_.name + ": " + error;
  }
  // With a key the vehicle must sign from the first frame on, unless we are to give it the
  // key (setup): then its unsigned frames count until it signs.
  ml::OpenResult opened = ml::Link::open(endpoint, handler, 1.0, key, key && !settings_.signing_setup);
  if (!opened.link) return opened.error;
  link_ = std::move(opened.link);
  link_->follow_only(wanted);

  std::unique_lock lock(first->mutex);
  auto wait = std::chrono::duration<double>(options_.connect_timeout_s);
  if (!first->cv.wait_for(lock, wait, [&] { return first->heard; })) {
    lock.unlock();
    char text[64];
    std::snprintf(text, sizeof text, "%.0f s", options_.connect_timeout_s);
    std::string who = wanted ? "system " + std::to_string(wanted) : std::string("any autopilot");
    std::string signing = key ? " Signing is on for this drone: unsigned or badly signed frames are dropped (" +
                                    std::to_string(link_->stats().signing_dropped) +
                                    " so far); does the vehicle have this key (`setup: true` gives it)?"
                              : "";
    link_.reset();
    return "no HEARTBEAT from " + who + " on " + endpoint.url + " within " + text +
           "; is the vehicle (or its SITL) running and sending to this address, with this system id?" + signing;
  }
  sysid_ = first->sysid;
  autopilot_ = autopilot_for(first->autopilot);
  if (!autopilot_) {
    link_.reset();
    return "system " + std::to_string(sysid_) + " on " + endpoint.url + " reports MAV_AUTOPILOT " +
           std::to_string(first->autopilot) + "; the mavlink adapter flies PX4 (12) and ArduPilot (3)";
  }
  link_->follow_only(sysid_);  // from now on only the vehicle's frames move a udp:// link
  encoder_ = {sysid_, ml::comp::ONBOARD_COMPUTER, 0};
  if (key) {
    if (std::string error = give_key(*first, lock, *key); !error.empty()) {
      lock.unlock();
      link_.reset();
      return error;
    }
    encoder_.signer.emplace(*key, kSigningLinkId);  // every frame from here on is signed
  }
  // Before the mission starts, so that its first deadline already knows how fast the
  // autopilot flies.
  std::map<std::string, float> values = read_params(*first, lock, limit_params(*autopilot_), options_.param_timeout_s,
                                                    [this](const char* name) {
                                                      send(ml::pack(ml::ParamRequestRead{sysid_, ml::comp::AUTOPILOT1, name, -1}));
                                                    });
  lock.unlock();
  limits_ = combine_limits(*autopilot_, settings_.limits, values);
  for (const std::string& w : limits_.warnings) diag::Logger{"mavlink", settings_.name}.warning(w);
  send_heartbeat();
  link_watchdog();
  return "";
}



// --- frames --------------------------------------------------------------------------------

void MavlinkDrone::on_frame(const ml::Frame& frame) {
  if (frame.sysid != sysid_) return;  // another vehicle (or a GCS) on the same port
  if (auto ack = ml::unpack_command_ack(frame.message)) {
    // MAV_RESULT ends at 9 (UNSUPPORTED_MAV_FRAME): an unknown result answers nothing;
    // the command is sent again and times out as unanswered if it never gets a real one.
    if (ack->result > kLastMavResult) return note_rejected("COMMAND_ACK with an unknown result");
    // An ACK addressed to another component (a GCS commanding the same vehicle) is not ours;
    // 0 means the autopilot did not say (older firmware).
    if (ack->target_component == 0 || ack->target_component == ml::comp::ONBOARD_COMPUTER)
      commands_.on_ack(*ack);
    return;
  }
  // From the autopilot or from a camera component of the same system.
  if (auto capture = ml::unpack_camera_capture(frame.message)) return on_camera_capture(*capture);
  if (auto hb = ml::unpack_heartbeat(frame.message); hb && hb->autopilot == ml::autopilot::INVALID)
    return;  // a camera, gimbal or companion of the same system: not the autopilot
  if (auto t = ml::unpack_statustext(frame.message); t && frame.compid == ml::comp::AUTOPILOT1)
    return on_statustext(*t);
  std::optional<ml::LocalPositionNed> report = ml::unpack_local_position_ned(frame.message);
  if (report) on_vehicle_clock(report->time_boot_ms);
  Changes c = apply_telemetry(vehicle_, frame);
  if (c.rejected) return note_rejected(c.rejected);
  if (c.armed) on_armed_changed();
  if (c.heartbeat) on_heartbeat();
  if (c.landed && vehicle_.landed()) {
    streaming_ = false;  // on the ground: nothing to hold
    in_control_ = false;
    disarm_after_failsafe_landing();
  }
  if (c.position || c.landed) check_goal();
  if (c.global_position && orbit_.commanded) correct_orbit_radius();
  if (c.armed || c.landed) end_motion_on_the_ground();
  if (c.position || c.armed || c.landed) publish();
}

// A failsafe ends with the motors off, as the simulator's does. An autopilot that does not
// disarm by itself after landing (ArduPilot DISARM_DELAY 0, PX4 COM_DISARM_LAND -1), or
// that takes its seconds to, would otherwise leave the vehicle armed on the ground when the
// DEX, which waits for its drone to be safe, ends. Refused (not landed yet, PX4 says), the
// autopilot's own auto-disarm remains, and the DEX waits for it.
void MavlinkDrone::disarm_after_failsafe_landing() {
  if (failsafe_reason_.empty() || !vehicle_.armed || disarm_commanded_) return;
  disarm_commanded_ = true;
  commands_.send(command(ml::cmd::COMPONENT_ARM_DISARM, {0.0f}), nullptr);
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
  streaming_ = false;
  in_control_ = false;
  fail_motion(mid::FailureReason::vehicle_fault,
              std::string(autopilot_->name) + " reports the vehicle on the ground and disarmed while " + r->name +
                  " ran: it cannot go on" + autopilot_says(tracker_.started_at(motion_owner_)),
              "landed and disarmed");
}

void MavlinkDrone::on_statustext(const ml::Statustext& t) {
  std::string text = t.text;
  if (t.id != 0) {
    // A text longer than 50 characters comes in chunks of one id; a chunk shorter than 50
    // is the last. Bounded: a sender that never ends a text cannot grow this without limit.
    std::string& pending = chunks_[t.id];
    pending += t.text;
    if (t.text.size() >= 50 && pending.size() < kMaxTextLength && chunks_.size() <= kMaxChunkedTexts) return;
    text = pending;
    chunks_.erase(t.id);
  }
  texts_.push_back({loop_.now(), t.severity, text});
  if (texts_.size() > kTextsKept) texts_.pop_front();
  note(std::string(autopilot_->name) + " " + severity_name(t.severity) + ": " + text);
}

// PX4 keeps its HEARTBEAT at 1 Hz (SET_MESSAGE_INTERVAL for it: MAV_RESULT_FAILED), armed
// state comes only with a HEARTBEAT, and a link that is not a ground station's gets none of
// its texts: a disarm would show up to a second late. On the ground, where its auto-disarms
// strike (COM_DISARM_PRFLT, COM_DISARM_LAND), one is asked for at heartbeat_hz with
// MAV_CMD_REQUEST_MESSAGE. In the air only a command or a crash disarms it; there it is asked
// for while PX4 flies an orbit, whose radius corrections go only right after a HEARTBEAT that
// shows the Orbit mode (send_due_orbit_correction): at PX4's 1 Hz they trailed the swing they
// correct.
void MavlinkDrone::poll_heartbeat() {
  heartbeat_poll_timer_ = loop_.after(mission_s(1.0 / options_.heartbeat_hz), [this] {
    heartbeat_poll_timer_ = mid::kNoTimer;
    poll_heartbeat();
  });
  if (link_lost_ || heartbeat_requested_ || !(vehicle_.landed() || orbit_.commanded)) return;
  heartbeat_requested_ = true;
  commands_.send(command(ml::cmd::REQUEST_MESSAGE, {static_cast<float>(ml::msg::HEARTBEAT)}),
                 [this](const CommandResult& result) {
                   heartbeat_requested_ = false;
                   if (!result.answered || result.accepted) return;
                   loop_.cancel(heartbeat_poll_timer_);  // an autopilot without REQUEST_MESSAGE
                   heartbeat_poll_timer_ = mid::kNoTimer;
                   note(std::string(autopilot_->name) + " refuses to send a HEARTBEAT when asked (" + result.error +
                        "): a disarm on the ground shows with its next one");
                 });
}

std::string MavlinkDrone::autopilot_says(double since) const {
  std::string said;
  for (const Text& t : texts_) {
    if (t.t < since || t.severity > kSeverityWarning) continue;
    if (said.find(t.text) != std::string::npos) continue;  // the same text repeated
    said += (said.empty() ? "" : "; ") + t.text;
  }
  return said.empty() ? "" : std::string("; ") + autopilot_->name + " says: " + said;
}

void MavlinkDrone::note(const std::string& text) {
  if (message_sink_) message_sink_(text);
}

// A disarm the mission did not ask for. On the ground after the mission's Arm it is the
// autopilot's auto-disarm (ArduPilot DISARM_DELAY, PX4 COM_DISARM_PRFLT): the next Takeoff
// arms again. The mission sees the drone disarmed meanwhile, as it is.
void MavlinkDrone::on_armed_changed() {
  if (vehicle_.armed || disarm_commanded_) return;
  if (takeoff_disarmed_on_ground()) return;
  if (armed_waiting_ && vehicle_.landed())
    note(std::string(autopilot_->name) + " disarmed the vehicle on the ground by itself (auto-disarm); "
         "eamos arms it again before its Takeoff");
  else if (!vehicle_.landed())
    note(std::string(autopilot_->name) + " reports the vehicle disarmed in the air");
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
                std::string(autopilot_->name) + " disarmed the vehicle again before it took off" +
                    autopilot_says(tracker_.started_at(id)),
                "disarmed on the ground twice during the takeoff");
    return true;
  }
  takeoff_rearmed_ = id;
  ++takeoff_attempt_;  // the NAV_TAKEOFF out now is not this takeoff's any more (send_takeoff)
  note(std::string(autopilot_->name) + " disarmed the vehicle on the ground during the takeoff (auto-disarm); "
       "eamos arms it again and repeats the takeoff");
  double altitude = r->args[0];
  streaming_ = false;
  in_control_ = false;
  start_takeoff(id, altitude);
  return true;
}

void MavlinkDrone::on_vehicle_clock(uint32_t time_boot_ms) {
  const double vehicle_s = time_boot_ms / 1000.0;
  // A reboot (or a reordered datagram) starts the window again.
  if (!clock_samples_.empty() && vehicle_s < clock_samples_.back().second) clock_samples_.clear();
  clock_samples_.push_back({loop_.now(), vehicle_s});
  while (clock_samples_.size() > 2 && clock_samples_.back().first - clock_samples_.front().first > 10.0)
    clock_samples_.pop_front();
  double rate = vehicle_clock_rate();
  if (rate < 0.8 && !clock_noted_) {
    clock_noted_ = true;
    char text[160];
    std::snprintf(text, sizeof text,
                  "the vehicle's clock runs at %.2f of mission time (a SITL slower than --speed?): deadlines are "
                  "stretched to match",
                  rate);
    note(text);
  }
}

double MavlinkDrone::vehicle_clock_rate() const {
  if (clock_samples_.size() < 2) return 1.0;
  double mission = clock_samples_.back().first - clock_samples_.front().first;
  if (mission < 2.0) return 1.0;  // too short to tell jitter from rate
  return (clock_samples_.back().second - clock_samples_.front().second) / mission;
}

double MavlinkDrone::deadline_clock_rate() const { return std::clamp(vehicle_clock_rate(), 0.2, 1.0); }

double MavlinkDrone::mission_s(double vehicle_s) const { return vehicle_s / deadline_clock_rate(); }

void MavlinkDrone::note_rejected(const char* what) {
  ++rejected_frames_;
  // The first few, then every thousandth: a flood of bad frames must not flood the log.
  if (rejected_frames_ <= 10 || rejected_frames_ % 1000 == 0)
    diag::Logger{"mavlink", settings_.name}.warning("dropped a frame of system " + std::to_string(sysid_) + ": " + what +
                                                    " (" + std::to_string(rejected_frames_) + " dropped so far)");
}

void MavlinkDrone::note_foreign() {
  uint64_t n = link_ ? link_->foreign_datagrams() : 0;
  if (n == foreign_reported_) return;
  bool first = foreign_reported_ == 0;
  bool thousandth = n / 1000 > foreign_reported_ / 1000;
  foreign_reported_ = n;
  if (!first && !thousandth) return;
  std::string text = "ignored " + std::to_string(n) + " datagram(s) from other addresses than system " +
                     std::to_string(sysid_) + "'s (not the vehicle: someone else is sending to this port)";
  diag::Logger{"mavlink", settings_.name}.warning(text);
  if (first) note(text);
}

void MavlinkDrone::on_heartbeat() {
  ++heartbeats_;
  note_foreign();
  if (link_lost_) {
    link_lost_ = false;
    publish();
  }
  link_watchdog();
  if (!telemetry_requested_) request_telemetry();
  if (left_orbit_mode()) return;
  send_due_orbit_correction();
  if (!streaming_ || !in_control_ || mode_commands_pending_ > 0) return;
  if (vehicle_.custom_mode == autopilot_->setpoint_mode) {
    mode_confirmed_ = true;
    return;
  }
  // mode_confirm_s (about 3 s) without the mode we were granted: it never took effect.
  if (!mode_confirmed_ && loop_.now() - mode_granted_at_ < options_.mode_confirm_s) return;
  // Someone else (a pilot's switch, the autopilot's own failsafe) took the vehicle out of
  // the setpoint mode: give way instead of switching back.
  streaming_ = false;
  in_control_ = false;
  std::string mode = mode_name(*autopilot_, vehicle_.custom_mode);
  fail_motion(mid::FailureReason::pilot_took_over,
              std::string("the vehicle left ") + autopilot_->setpoint_mode_name + " for " + mode, "mode " + mode);
}

void MavlinkDrone::fail_motion(mid::FailureReason why, const std::string& reason, const std::string& detail) {
  if (motion_owner_ == mid::kNoAction) return;
  ActionId id = motion_owner_;
  motion_owner_ = mid::kNoAction;
  goal_.reset();
  orbit_ = {};
  tracker_.fail(id, why, reason, detail);
}

void MavlinkDrone::link_watchdog() {
  loop_.cancel(watchdog_timer_);
  // Like the deadlines, in the vehicle's time: a slow SITL sends its heartbeats slower.
  watchdog_timer_ = loop_.after(mission_s(options_.link_timeout_s), [this] {
    watchdog_timer_ = mid::kNoTimer;
    lose_link();
  });
}

void MavlinkDrone::lose_link() {
  link_lost_ = true;
  telemetry_requested_ = false;  // ask again when it is back: the vehicle may have rebooted
  streaming_ = false;
  in_control_ = false;
  char text[128];
  std::snprintf(text, sizeof text, "link lost: no HEARTBEAT from system %d for %.1f s", sysid_,
                options_.link_timeout_s);
  fail_all(mid::FailureReason::link_lost, text);
  commands_.fail_all("link lost");
  publish();
}

void MavlinkDrone::request_telemetry() {
  telemetry_requested_ = true;
  struct Rate { uint32_t id; double hz; };
  for (Rate r : {Rate{ml::msg::HEARTBEAT, options_.heartbeat_hz}, Rate{ml::msg::LOCAL_POSITION_NED, options_.position_hz},
                 Rate{ml::msg::EXTENDED_SYS_STATE, 2.0},
                 // At the position rate: an orbit's radius is measured from it (mavlink_drone_orbit.cpp).
                 Rate{ml::msg::GLOBAL_POSITION_INT, options_.position_hz}, Rate{ml::msg::ORBIT_EXECUTION_STATUS, 2.0},
                 Rate{ml::msg::SYS_STATUS, 1.0}, Rate{ml::msg::BATTERY_STATUS, 1.0}}) {
    // Only from an autopilot that flies DO_ORBIT: ArduCopter has no such stream and answers
    // with a STATUSTEXT ("No ap_message for mavlink id (360)") in every trace.
    if (r.id == ml::msg::ORBIT_EXECUTION_STATUS && !autopilot_->do_orbit) continue;
    // An autopilot that refuses a rate still streams its defaults: HEARTBEAT is then asked
    // for on the ground (poll_heartbeat), for the others nothing is to be done.
    CommandDone done = nullptr;
    if (r.id == ml::msg::HEARTBEAT)
      done = [this](const CommandResult& result) {
        if (!result.answered || result.accepted || heartbeat_poll_timer_ != mid::kNoTimer) return;
        char hz[32];
        std::snprintf(hz, sizeof hz, "%.0f Hz", options_.heartbeat_hz);
        note(std::string(autopilot_->name) + " keeps its HEARTBEAT rate (" + result.error +
             "): on the ground eamos asks for one at " + hz + ", so an auto-disarm shows at once");
        poll_heartbeat();
      };
    commands_.send(command(ml::cmd::SET_MESSAGE_INTERVAL,
                           {static_cast<float>(r.id), static_cast<float>(1e6 / r.hz)}),
                   std::move(done));
  }
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
  holding_ = setpoint_ = goal_target;
  stream_setpoints();
}

// --- sending -------------------------------------------------------------------------------

void MavlinkDrone::send(const ml::Message& m) {
  if (link_) link_->send(encoder_.encode(m));
}

void MavlinkDrone::send_heartbeat() {
  ml::Heartbeat hb;
  hb.type = ml::mav_type::ONBOARD_CONTROLLER;
  hb.autopilot = ml::autopilot::INVALID;
  hb.system_status = ml::state::ACTIVE;
  send(ml::pack(hb));
  if (settings_.announce_as_gcs) {
    // PX4 sends STATUSTEXT (why it refused) only to a link where it heard a ground station
    // within 2.5 s. Asked for in the fleet file: it also keeps PX4's GCS link-loss failsafe
    // from seeing the real ground station go (docs/fleet.md, docs/adapters.md).
    hb.type = ml::mav_type::GCS;
    send(ml::pack(hb));
  }
  heartbeat_timer_ = loop_.after(1.0, [this] { send_heartbeat(); });
}

ml::CommandLong MavlinkDrone::command(uint16_t id, std::array<float, 7> params) const {
  ml::CommandLong c;
  c.target_system = sysid_;
  c.target_component = ml::comp::AUTOPILOT1;
  c.command = id;
  c.param = params;
  return c;
}

// --- setpoints -----------------------------------------------------------------------------

void MavlinkDrone::stream_setpoints() {
  streaming_ = true;
  if (stream_timer_ != mid::kNoTimer) return;
  setpoints_sent_ = 0;
  stream_tick();
}

void MavlinkDrone::stream_tick() {
  stream_timer_ = mid::kNoTimer;
  if (!streaming_ || link_lost_) return;
  const double dt = 1.0 / options_.setpoint_hz;
  if (orbit_.active) advance_orbit(dt);
  ml::SetPositionTargetLocalNed sp;
  sp.time_boot_ms = static_cast<uint32_t>(loop_.now() * 1000.0);
  sp.target_system = sysid_;
  sp.target_component = ml::comp::AUTOPILOT1;
  sp.coordinate_frame = ml::kFrameLocalNed;
  sp.type_mask = ml::kPositionOnlyMask;
  Vec3 ned = mission_to_ned(setpoint_, settings_.home);
  sp.x = static_cast<float>(ned.x);
  sp.y = static_cast<float>(ned.y);
  sp.z = static_cast<float>(ned.z);
  if (std::optional<double> yaw = orbit_setpoint_yaw()) {
    sp.type_mask = ml::kPositionAndYawMask;
    sp.yaw = static_cast<float>(*yaw);
  }
  send(ml::pack(sp));
  ++setpoints_sent_;
  if (!in_control_ && mode_commands_pending_ == 0 &&
      (!autopilot_->stream_before_switch || setpoints_sent_ >= options_.setpoints_before_switch))
    switch_to_setpoint_mode();
  stream_timer_ = loop_.after(dt, [this] { stream_tick(); });
}

void MavlinkDrone::switch_to_setpoint_mode() {
  if (vehicle_.custom_mode == autopilot_->setpoint_mode) {
    in_control_ = true;
    mode_confirmed_ = true;
    return;
  }
  auto p = set_mode_params(*autopilot_, autopilot_->setpoint_mode);
  send_mode_command(command(ml::cmd::DO_SET_MODE, {p[0], p[1], p[2]}), [this](const CommandResult& r) {
    if (r.accepted) {
      in_control_ = true;
      mode_confirmed_ = false;
      mode_granted_at_ = loop_.now();
      return;
    }
    streaming_ = false;
    fail_motion(r.answered ? mid::FailureReason::refused : mid::FailureReason::timed_out,
                std::string("switch to ") + autopilot_->setpoint_mode_name + " refused by " + autopilot_->name +
                    ": " + r.error,
                r.error);
  });
}

CommandDone MavlinkDrone::counted_mode_command(CommandDone done) {
  ++mode_commands_pending_;
  return [this, done = std::move(done)](const CommandResult& r) {
    --mode_commands_pending_;
    if (done) done(r);
  };
}

void MavlinkDrone::send_mode_command(ml::CommandLong c, CommandDone done, std::function<bool()> resend_while) {
  commands_.send(c, counted_mode_command(std::move(done)), std::move(resend_while));
}

void MavlinkDrone::send_mode_command(const ml::CommandInt& c, CommandDone done) {
  commands_.send(c, counted_mode_command(std::move(done)));
}

}  // namespace eamos::mavlink_adapter
