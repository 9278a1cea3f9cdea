#pragma once
// Whether the vehicle is still heard. Its HEARTBEATs rearm a watchdog of link_timeout_s (in
// the vehicle's time: a slow SITL sends them slower); none for that long and the link is
// lost until the next one. After every (re)connection the telemetry is asked for again (the
// vehicle may have rebooted). An autopilot that keeps its own HEARTBEAT rate is asked for one
// at heartbeat_hz while that matters: on the ground, where auto-disarms strike, and while it
// flies DO_ORBIT, whose corrections go right after a HEARTBEAT.
#include <cstdint>
#include <functional>
#include <string>

#include "mavlink_adapter/command_sender.h"
#include "mavlink_adapter/mavlink_options.h"
#include "mavlink_adapter/vehicle_clock.h"
#include "mavlink_adapter/vehicle_link.h"
#include "mid/event_loop.h"

namespace eamos::mavlink_adapter {

class LinkWatch {
 public:
  struct Hooks {
    std::function<void(const std::string& why)> lost;  ///< the link was just lost
    std::function<void()> back;                         ///< a HEARTBEAT after a loss
    std::function<bool()> poll_wanted;  ///< a HEARTBEAT on request is worth asking for now
    std::function<void(const std::string&)> note;       ///< to the trace
  };
  LinkWatch(mid::EventLoop& loop, const MavlinkOptions& options, VehicleLink& link, CommandSender& commands,
            const VehicleClock& clock, Hooks hooks);
  ~LinkWatch();
  LinkWatch(const LinkWatch&) = delete;
  LinkWatch& operator=(const LinkWatch&) = delete;

  /// Arms the watchdog (after connect).
  void start() { rearm(); }
  /// An autopilot HEARTBEAT was folded in.
  void on_heartbeat();
  bool lost() const { return lost_; }
  uint64_t heartbeats() const { return heartbeats_; }  ///< autopilot HEARTBEATs so far

 private:
  void rearm();
  void lose();
  void request_telemetry();
  /// MAV_CMD_REQUEST_MESSAGE(HEARTBEAT) at heartbeat_hz while poll_wanted().
  void poll_heartbeat();

  mid::EventLoop& loop_;
  const MavlinkOptions& options_;
  VehicleLink& link_;
  CommandSender& commands_;
  const VehicleClock& clock_;
  Hooks hooks_;
  bool lost_ = false;
  bool telemetry_requested_ = false;
  uint64_t heartbeats_ = 0;
  bool heartbeat_requested_ = false;  ///< a REQUEST_MESSAGE(HEARTBEAT) waits for its ACK
  mid::TimerId watchdog_timer_ = mid::kNoTimer;
  mid::TimerId poll_timer_ = mid::kNoTimer;  ///< poll_heartbeat's; none: the rate was granted
};

}  // namespace eamos::mavlink_adapter
