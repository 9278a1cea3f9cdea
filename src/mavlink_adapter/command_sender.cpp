#include "mavlink_adapter/command_sender.h"

#include <cstdio>
#include <utility>
#include <vector>

#include "mavlink/enums.h"

namespace eamos::mavlink_adapter {

namespace ml = eamos::mavlink;

CommandSender::CommandSender(mid::EventLoop& loop, Transmit transmit, CommandOptions options)
    : loop_(loop), transmit_(std::move(transmit)), options_(options) {}

CommandSender::~CommandSender() {
  for (auto& [id, queue] : queues_)
    for (Pending& p : queue) loop_.cancel(p.timer);
}

void CommandSender::send(ml::CommandLong command, CommandDone done, std::function<bool()> resend_while) {
  command.confirmation = 0;
  auto& queue = queues_[command.command];
  queue.push_back({command, std::nullopt, std::move(done), std::move(resend_while)});
  if (queue.size() == 1) transmit_head(command.command);
}

void CommandSender::send(const ml::CommandInt& command, CommandDone done, std::function<bool()> resend_while) {
  ml::CommandLong key{command.target_system, command.target_component, command.command, 0, {}};
  auto& queue = queues_[command.command];
  queue.push_back({key, command, std::move(done), std::move(resend_while)});
  if (queue.size() == 1) transmit_head(command.command);
}

void CommandSender::transmit_head(uint16_t id) {
  Pending& p = queues_[id].front();
  transmit_(p.as_int ? ml::pack(*p.as_int) : ml::pack(p.command));
  p.timer = loop_.after(options_.ack_timeout_s, [this, id] { timed_out(id); });
}

void CommandSender::timed_out(uint16_t id) {
  auto it = queues_.find(id);
  if (it == queues_.end() || it->second.empty()) return;
  Pending& p = it->second.front();
  p.timer = mid::kNoTimer;
  if (p.resend_while && !p.resend_while()) {
    finish(id, {false, ml::command_name(id) + ": no COMMAND_ACK, and not sent again: no longer wanted"});
    return;
  }
  if (p.command.confirmation < options_.retries) {
    ++p.command.confirmation;  // tells the autopilot this is a resend, not a new command
    transmit_head(id);
    return;
  }
  char text[160];
  std::snprintf(text, sizeof text, "%s: no COMMAND_ACK after %d tries (%.1f s each)",
                ml::command_name(id).c_str(), options_.retries + 1, options_.ack_timeout_s);
  finish(id, {false, text});
}

void CommandSender::on_ack(const ml::CommandAck& ack) {
  auto it = queues_.find(ack.command);
  if (it == queues_.end() || it->second.empty()) return;  // a late duplicate: already done
  Pending& p = it->second.front();
  loop_.cancel(p.timer);
  p.timer = mid::kNoTimer;
  if (ack.result == ml::result::IN_PROGRESS) {
    uint16_t id = ack.command;
    p.timer = loop_.after(options_.in_progress_s, [this, id] {
      finish(id, {false, ml::command_name(id) + ": reported in progress, then no final COMMAND_ACK"});
    });
    return;
  }
  if (ack.result == ml::result::ACCEPTED) finish(ack.command, {true, "", true});
  else finish(ack.command, {false, ml::command_name(ack.command) + ": " + ml::result_text(ack.result), true});
}

void CommandSender::finish(uint16_t id, CommandResult result) {
  auto& queue = queues_[id];
  std::vector<std::pair<CommandDone, CommandResult>> ended;
  ended.emplace_back(std::move(queue.front().done), std::move(result));
  loop_.cancel(queue.front().timer);
  queue.pop_front();
  // A command that waited behind this one and is no longer wanted is not sent at all: an
  // ARM for an action that has ended since must not reach a vehicle in its failsafe.
  while (!queue.empty() && queue.front().resend_while && !queue.front().resend_while()) {
    ended.emplace_back(std::move(queue.front().done),
                       CommandResult{false, ml::command_name(id) + ": not sent: no longer wanted"});
    queue.pop_front();
  }
  if (!queue.empty()) transmit_head(id);
  else queues_.erase(id);
  for (auto& [done, r] : ended)
    if (done) done(r);
}

void CommandSender::fail_all(const std::string& error) {
  std::map<uint16_t, std::deque<Pending>> queues;
  queues.swap(queues_);
  for (auto& [id, queue] : queues)
    for (Pending& p : queue) {
      loop_.cancel(p.timer);
      if (p.done) p.done({false, ml::command_name(id) + ": " + error});
    }
}

size_t CommandSender::pending() const {
  size_t n = 0;
  for (const auto& [id, queue] : queues_) n += queue.size();
  return n;
}

}  // namespace eamos::mavlink_adapter
