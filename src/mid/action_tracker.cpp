#include "mid/action_tracker.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "mid/timeouts.h"

namespace eamos::mid {

namespace {
std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f s", s);
  return buf;
}
}  // namespace

ActionTracker::ActionTracker(EventLoop& loop, std::function<void(ActionId)> on_timeout,
                             std::function<std::string(ActionId)> describe,
                             std::function<double(ActionId)> distance_left)
    : loop_(loop),
      on_timeout_(std::move(on_timeout)),
      describe_(std::move(describe)),
      distance_left_(std::move(distance_left)) {}

ActionTracker::~ActionTracker() {
  for (ActionId id : running_ids()) end(id, Outcome::cancelled, "drone shut down");
}

ActionId ActionTracker::begin(const ActionRequest& request, fleet::ActionClass action_class,
                              EndCallback on_end, double timeout_s, double closing_window_s,
                              double vehicle_clock_rate) {
  if (action_class == fleet::ActionClass::motion && motion_ != kNoAction)
    end(motion_, Outcome::preempted, "preempted by " + request.name);
  ActionId id = next_id_++;
  Running r{request, action_class, std::move(on_end), loop_.now(), kNoTimer};
  r.timeout_s = timeout_s;
  r.clock_rate = vehicle_clock_rate;
  // A window as long as the deadline would start before the goal is set: none then.
  if (distance_left_ && closing_window_s > 0.0 && closing_window_s < timeout_s) r.window_s = closing_window_s;
  actions_.emplace(id, std::move(r));
  if (action_class == fleet::ActionClass::motion) motion_ = id;
  if (std::isfinite(timeout_s)) {
    const double window = actions_.at(id).window_s;
    arm(id, timeout_s - window, window > 0.0);
  }
  return id;
}

void ActionTracker::arm(ActionId id, double delay_s, bool probe) {
  Running& r = actions_.at(id);
  r.due = loop_.now() + delay_s;
  r.due_probe = probe;
  r.deadline = loop_.after(delay_s, [this, id, probe] {
    auto it = actions_.find(id);
    if (it == actions_.end()) return;
    it->second.deadline = kNoTimer;  // firing now; end() must not cancel it
    if (!probe) return deadline_passed(id);
    it->second.window_from_m = distance_left_(id);  // a window exists only with distance_left_
    arm(id, it->second.window_s, false);
  });
}

// The deadline: moved on by a window while the vehicle still closes in, else the action fails.
void ActionTracker::deadline_passed(ActionId id) {
  Running& r = actions_.at(id);
  // Without a window (or with the whole extension spent) the adapter is not even asked.
  if (r.window_s <= 0.0 || r.granted_s + r.window_s > r.timeout_s + 1e-9) return time_out(id);
  const double now_m = distance_left_(id);
  const bool closed_in = std::isfinite(now_m) && std::isfinite(r.window_from_m) && r.window_from_m - now_m >= kClosingMin_m;
  if (!closed_in) return time_out(id);
  r.granted_s += r.window_s;
  r.window_from_m = now_m;
  arm(id, r.window_s, false);
}

void ActionTracker::time_out(ActionId id) {
  const Running& r = actions_.at(id);
  const double timeout_s = r.timeout_s, granted_s = r.granted_s;
  std::string detail = deadline_text(r);
  const std::string where = describe_ ? describe_(id) : "";  // before the stop clears the goal
  on_timeout_(id);
  std::string reason = "timed out after " + seconds_text(timeout_s + granted_s);
  if (granted_s > 0.0) {
    reason += ", " + seconds_text(granted_s) + " of them given while it still closed in on its goal";
    detail += ", extended by " + seconds_text(granted_s);
  }
  fail(id, FailureReason::timed_out, reason + (where.empty() ? "" : " (" + where + ")"), detail);
}

// In the fleet file's seconds first: a deadline stretched for a vehicle whose clock runs slow
// (a SITL that cannot keep up) would otherwise read as a different deadline than was written.
std::string ActionTracker::deadline_text(const Running& r) {
  if (r.clock_rate >= 0.995 || r.clock_rate <= 0.0)
    return "deadline " + seconds_text(r.timeout_s) + " after start";
  char rate[16];
  std::snprintf(rate, sizeof rate, "%.2f", r.clock_rate);
  return "deadline " + seconds_text(r.timeout_s * r.clock_rate) + " of the vehicle's clock after start (" +
         seconds_text(r.timeout_s) + " of mission time: the vehicle's clock ran at " + rate + " of it)";
}

bool ActionTracker::pause(ActionId id) {
  auto it = actions_.find(id);
  if (it == actions_.end() || it->second.paused) return false;
  Running& r = it->second;
  r.paused = true;
  r.paused_left = -1.0;  // no deadline armed: nothing to re-arm
  if (r.deadline != kNoTimer) {
    r.paused_left = std::max(0.0, r.due - loop_.now());
    loop_.cancel(r.deadline);
    r.deadline = kNoTimer;
  }
  return true;
}

bool ActionTracker::unpause(ActionId id) {
  auto it = actions_.find(id);
  if (it == actions_.end() || !it->second.paused) return false;
  Running& r = it->second;
  r.paused = false;
  if (r.paused_left >= 0.0) arm(id, r.paused_left, r.due_probe);
  return true;
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
