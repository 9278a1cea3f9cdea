#include "mavlink_adapter/link_watch.h"

#include <cstdio>

#include "mavlink/enums.h"

namespace eamos::mavlink_adapter {

namespace ml = eamos::mavlink;

LinkWatch::LinkWatch(mid::EventLoop& loop, const MavlinkOptions& options, VehicleLink& link,
                     CommandSender& commands, const VehicleClock& clock, Hooks hooks)
    : loop_(loop), options_(options), link_(link), commands_(commands), clock_(clock), hooks_(std::move(hooks)) {}

LinkWatch::~LinkWatch() {
  loop_.cancel(watchdog_timer_);
  loop_.cancel(poll_timer_);
}

void LinkWatch::on_heartbeat() {
  ++heartbeats_;
  if (lost_) {
    lost_ = false;
    hooks_.back();
  }
  rearm();
  if (!telemetry_requested_) request_telemetry();
}

void LinkWatch::rearm() {
  loop_.cancel(watchdog_timer_);
  // Like the deadlines, in the vehicle's time: a slow SITL sends its heartbeats slower.
  watchdog_timer_ = loop_.after(clock_.mission_s(options_.link_timeout_s), [this] {
    watchdog_timer_ = mid::kNoTimer;
    lose();
  });
}

void LinkWatch::lose() {
  lost_ = true;
  telemetry_requested_ = false;  // ask again when it is back: the vehicle may have rebooted
  char text[128];
  std::snprintf(text, sizeof text, "link lost: no HEARTBEAT from system %d for %.1f s", link_.sysid(),
                options_.link_timeout_s);
  hooks_.lost(text);
}

void LinkWatch::request_telemetry() {
  telemetry_requested_ = true;
  struct Rate { uint32_t id; double hz; };
  for (Rate r : {Rate{ml::msg::HEARTBEAT, options_.heartbeat_hz}, Rate{ml::msg::LOCAL_POSITION_NED, options_.position_hz},
                 Rate{ml::msg::EXTENDED_SYS_STATE, 2.0},
                 // At the position rate: an orbit's radius is measured from it (orbit_flight.cpp).
                 Rate{ml::msg::GLOBAL_POSITION_INT, options_.position_hz}, Rate{ml::msg::ORBIT_EXECUTION_STATUS, 2.0},
                 Rate{ml::msg::SYS_STATUS, 1.0}, Rate{ml::msg::BATTERY_STATUS, 1.0}}) {
    // Only from an autopilot that flies DO_ORBIT: ArduCopter has no such stream and answers
    // with a STATUSTEXT ("No ap_message for mavlink id (360)") in every trace.
    if (r.id == ml::msg::ORBIT_EXECUTION_STATUS && !link_.autopilot()->do_orbit) continue;
    // An autopilot that refuses a rate still streams its defaults: HEARTBEAT is then asked
    // for on the ground (poll_heartbeat), for the others nothing is to be done.
    CommandDone done = nullptr;
    if (r.id == ml::msg::HEARTBEAT)
      done = [this](const CommandResult& result) {
        if (!result.answered || result.accepted || poll_timer_ != mid::kNoTimer) return;
        char hz[32];
        std::snprintf(hz, sizeof hz, "%.0f Hz", options_.heartbeat_hz);
        hooks_.note(std::string(link_.autopilot()->name) + " keeps its HEARTBEAT rate (" + result.error +
                    "): on the ground eamos asks for one at " + hz + ", so an auto-disarm shows at once");
        poll_heartbeat();
      };
    commands_.send(link_.command(ml::cmd::SET_MESSAGE_INTERVAL,
                                 {static_cast<float>(r.id), static_cast<float>(1e6 / r.hz)}),
                   std::move(done));
  }
}

// PX4 keeps its HEARTBEAT at 1 Hz (SET_MESSAGE_INTERVAL for it: MAV_RESULT_FAILED), armed
// state comes only with a HEARTBEAT, and a link that is not a ground station's gets none of
// its texts: a disarm would show up to a second late. On the ground, where its auto-disarms
// strike (COM_DISARM_PRFLT, COM_DISARM_LAND), one is asked for at heartbeat_hz with
// MAV_CMD_REQUEST_MESSAGE. In the air only a command or a crash disarms it; there it is asked
// for while PX4 flies an orbit, whose radius corrections go only right after a HEARTBEAT that
// shows the Orbit mode (OrbitFlight::send_due_correction): at PX4's 1 Hz they trailed the
// swing they correct.
void LinkWatch::poll_heartbeat() {
  poll_timer_ = loop_.after(clock_.mission_s(1.0 / options_.heartbeat_hz), [this] {
    poll_timer_ = mid::kNoTimer;
    poll_heartbeat();
  });
  if (lost_ || heartbeat_requested_ || !hooks_.poll_wanted()) return;
  heartbeat_requested_ = true;
  commands_.send(link_.command(ml::cmd::REQUEST_MESSAGE, {static_cast<float>(ml::msg::HEARTBEAT)}),
                 [this](const CommandResult& result) {
                   heartbeat_requested_ = false;
                   if (!result.answered || result.accepted) return;
                   loop_.cancel(poll_timer_);  // an autopilot without REQUEST_MESSAGE
                   poll_timer_ = mid::kNoTimer;
                   hooks_.note(std::string(link_.autopilot()->name) + " refuses to send a HEARTBEAT when asked (" +
                               result.error + "): a disarm on the ground shows with its next one");
                 });
}

}  // namespace eamos::mavlink_adapter
