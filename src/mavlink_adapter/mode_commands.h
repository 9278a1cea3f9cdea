#pragma once
// Commands that change the flight mode (DO_SET_MODE, NAV_TAKEOFF, NAV_LAND,
// NAV_RETURN_TO_LAUNCH, DO_ORBIT), counted while they are out: meanwhile a HEARTBEAT in
// another mode is expected, not somebody taking over, and the setpoint stream does not ask
// for its mode again.
#include <functional>

#include "mavlink_adapter/command_sender.h"

namespace eamos::mavlink_adapter {

class ModeCommands {
 public:
  explicit ModeCommands(CommandSender& commands) : commands_(commands) {}

  void send(mavlink::CommandLong c, CommandDone done, std::function<bool()> resend_while = nullptr) {
    commands_.send(c, counted(std::move(done)), std::move(resend_while));
  }
  void send(const mavlink::CommandInt& c, CommandDone done) { commands_.send(c, counted(std::move(done))); }
  /// A mode command is out: the vehicle's mode may change any moment.
  bool pending() const { return pending_ > 0; }

 private:
  CommandDone counted(CommandDone done) {
    ++pending_;
    return [this, done = std::move(done)](const CommandResult& r) {
      --pending_;
      if (done) done(r);
    };
  }

  CommandSender& commands_;
  int pending_ = 0;
};

}  // namespace eamos::mavlink_adapter
