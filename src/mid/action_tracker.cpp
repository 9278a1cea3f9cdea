#include "mid/action_tracker.h"

#include <cmath>
#include <cstdio>

namespace eamos::mid {

namespace {
std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f s", s);
  return buf;
}
}  // namespace

ActionTracker::ActionTracker(EventLoop& loop, std::function<void(ActionId)> on_timeout,
                             std::function<std::string(ActionId)> describe)
    : loop_(loop), on_timeout_(std::move(on_timeout)), describe_(std::move(describe)) {}

ActionTracker::~ActionTracker() {
  for (ActionId id : running_ids()) end(id, Outcome::cancelled, "drone shut down");
}

ActionId ActionTracker::begin(const ActionRequest& request, fleet::ActionClass action_class,
                              EndCallback on_end, double timeout_s) {
  if (action_class == fleet::ActionClass::motion && motion_ != kNoAction)
    end(motion_, Outcome::preempted, "preempted by " + request.name);
  ActionId id = next_id_++;
  TimerId deadline = kNoTimer;
  if (std::isfinite(timeout_s)) {
    deadline = loop_.after(timeout_s, [this, id, timeout_s] {
      auto it = actions_.find(id);
      if (it == actions_.end()) return;
      it->second.deadline = kNoTimer;  // firing now; end() must not cancel it
      const std::string where = describe_ ? describe_(id) : "";  // before the stop clears the goal
      on_timeout_(id);
      fail(id, FailureReason::timed_out,
           "timed out after " + seconds_text(timeout_s) + (where.empty() ? "" : " (" + where + ")"),
           "deadline " + seconds_text(timeout_s) + " after start");
    });
  }
  actions_.emplace(id, Running{request, action_class, std::move(on_end), loop_.now(), deadline});
  if (action_class == fleet::ActionClass::motion) motion_ = id;
  return id;
}

ActionId ActionTracker::refuse(const ActionRequest&, EndCallback on_end, ActionEnd why) {
  ActionId id = next_id_++;
  why.outcome = Outcome::failed;
  if (why.failure == FailureReason::none) why.failure = FailureReason::refused;
  report(std::move(on_end), std::move(why));
  return id;
}

bool ActionTracker::end(ActionId id, Outcome outcome, std::string reason,
                        std::optional<double> value) {
  return end(id, ActionEnd{outcome, std::move(reason), value});
}

bool ActionTracker::fail(ActionId id, FailureReason why, std::string reason, std::string detail) {
  return end(id, ActionEnd{Outcome::failed, std::move(reason), std::nullopt, why, std::move(detail)});
}

bool ActionTracker::end(ActionId id, ActionEnd e) {
  // A failure always names its kind: one that would not is a vehicle fault, never "none".
  if (e.outcome == Outcome::failed && e.failure == FailureReason::none) e.failure = FailureReason::vehicle_fault;
  if (e.outcome != Outcome::failed) e.failure = FailureReason::none;
  auto it = actions_.find(id);
  if (it == actions_.end()) return false;
  Running r = std::move(it->second);
  actions_.erase(it);
  if (r.deadline != kNoTimer) loop_.cancel(r.deadline);
  if (motion_ == id) motion_ = kNoAction;
  report(std::move(r.on_end), std::move(e));
  return true;
}

void ActionTracker::report(EndCallback on_end, ActionEnd end) {
  // Through the loop, never directly: the caller may be inside start() or cancel(), and a
  // DEX reacting to an end must never re-enter the adapter that reports it.
  loop_.after(0.0, [fn = std::move(on_end), end = std::move(end)] {
    if (fn) fn(end);
  });
}

std::vector<ActionId> ActionTracker::running_ids() const {
  std::vector<ActionId> ids;
  for (const auto& [id, r] : actions_) ids.push_back(id);
  return ids;
}

const ActionRequest* ActionTracker::request(ActionId id) const {
  auto it = actions_.find(id);
  return it == actions_.end() ? nullptr : &it->second.request;
}

double ActionTracker::started_at(ActionId id) const {
  auto it = actions_.find(id);
  return it == actions_.end() ? 0.0 : it->second.started_at;
}

}  // namespace eamos::mid
