#pragma once
// COMMAND_LONG with acknowledgement: send, wait for the COMMAND_ACK, resend with the
// confirmation field counted up when none comes, give up after the last retry. MAVLink
// matches an ACK to its command by the command id alone, so at most one command of each id is
// in flight; later ones of the same id wait in a queue (SET_MESSAGE_INTERVAL for several
// messages, say). Runs on the event loop; done callbacks run from on_ack or a timer, never
// from send().
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "mavlink/payloads.h"
#include "mid/event_loop.h"

namespace eamos::mavlink_adapter {

struct CommandOptions {
  double ack_timeout_s = 1.0;  ///< wait for an ACK this long (mission s) before resending
  int retries = 3;             ///< resends after the first try
  double in_progress_s = 10.0; ///< after MAV_RESULT_IN_PROGRESS wait this long for the final ACK
};

struct CommandResult {
  bool accepted = false;
  std::string error;  ///< "" when accepted; else the command and the MAV_RESULT (or no ACK) in words
  bool answered = false;  ///< the vehicle sent a final COMMAND_ACK (accepted or not)
};
using CommandDone = std::function<void(const CommandResult&)>;

class CommandSender {
 public:
  using Transmit = std::function<void(const mavlink::Message&)>;
  CommandSender(mid::EventLoop& loop, Transmit transmit, CommandOptions options = {});
  ~CommandSender();
  CommandSender(const CommandSender&) = delete;
  CommandSender& operator=(const CommandSender&) = delete;

  /// Queues `command` (confirmation is set here); `done` runs once with the outcome. With
  /// `resend_while`, a command whose ACK is late is sent again only while it returns true,
  /// and one that waited behind another of its id is sent at all only if it returns true
  /// then: a command that is no longer wanted must not reach the vehicle after the ones that
  /// replaced it (it then ends unanswered at once).
  void send(mavlink::CommandLong command, CommandDone done, std::function<bool()> resend_while = nullptr);
  /// The same for a COMMAND_INT (a command with a position in degE7, exact where a float is
  /// not); it has no confirmation field, so a resend is the same frame again.
  void send(const mavlink::CommandInt& command, CommandDone done, std::function<bool()> resend_while = nullptr);
  /// Feeds a COMMAND_ACK from the vehicle.
  void on_ack(const mavlink::CommandAck& ack);
  /// Ends every queued command with `error` (the link is gone).
  void fail_all(const std::string& error);
  /// Commands waiting or in flight.
  size_t pending() const;

 private:
  struct Pending {
    mavlink::CommandLong command;  ///< its id and confirmation count; sent as is unless as_int
    std::optional<mavlink::CommandInt> as_int;
    CommandDone done;
    std::function<bool()> resend_while;
    mid::TimerId timer = mid::kNoTimer;
  };
  void transmit_head(uint16_t id);
  void timed_out(uint16_t id);
  void finish(uint16_t id, CommandResult result);

  mid::EventLoop& loop_;
  Transmit transmit_;
  CommandOptions options_;
  std::map<uint16_t, std::deque<Pending>> queues_;  ///< per command id; the head is in flight
};

}  // namespace eamos::mavlink_adapter
