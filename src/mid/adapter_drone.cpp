#include "mid/adapter_drone.h"

namespace eamos::mid {

AdapterDrone::AdapterDrone(EventLoop& loop, fleet::DroneType type)
    : loop_(loop),
      type_(std::move(type)),
      tracker_(
          loop,
          [this](ActionId id) {
            clear_action_timer(id);
            stop_action(id);
          },
          [this](ActionId id) { return timeout_detail(id); },
          [this](ActionId id) { return distance_left(id); }) {}

AdapterDrone::~AdapterDrone() {
  for (auto& [id, timer] : action_timers_) loop_.cancel(timer);
}

ActionId AdapterDrone::start(const ActionRequest& request, EndCallback on_end) {
  if (!failsafe_reason_.empty())
    return tracker_.refuse(request, std::move(on_end),
                           {.reason = "failsafe active (" + failsafe_reason_ + ")", .failure = FailureReason::refused});
  if (std::optional<ActionEnd> why = unavailable()) return tracker_.refuse(request, std::move(on_end), *why);
  RequestCheck check = check_request(request, type_);
  if (!check.spec)
    return tracker_.refuse(request, std::move(on_end), {.reason = check.error, .failure = FailureReason::refused});
  if (std::string why = refusal(request, *check.spec); !why.empty())
    return tracker_.refuse(request, std::move(on_end), {.reason = why, .failure = FailureReason::refused});

  double timeout = timeout_for(request);
  fleet::ActionClass cls = check.spec->action_class;
  if (cls == fleet::ActionClass::motion) clear_action_timer(tracker_.motion());  // preempted
  ActionId id = tracker_.begin(request, cls, std::move(on_end), timeout, closing_window_s(request),
                                 deadline_clock_rate());
  switch (cls) {
    case fleet::ActionClass::system: start_system(id, request); break;
    case fleet::ActionClass::payload: start_payload(id, request); break;
    case fleet::ActionClass::motion: start_motion(id, request); break;
  }
  started();
  return id;
}

bool AdapterDrone::cancel(ActionId id) {
  if (!tracker_.running(id)) return false;
  clear_action_timer(id);
  stop_action(id);
  tracker_.end(id, Outcome::cancelled, "cancelled");
  return true;
}

bool AdapterDrone::hold_motion(double climb_m) {
  const ActionId id = tracker_.motion();
  if (id == kNoAction || motion_held() || !failsafe_reason_.empty()) return false;
  const ActionRequest* r = tracker_.request(id);
  if (!r || !goal_position(*r, {}, {})) return false;  // Hover, Orbit: no goal to resume
  if (!hold_vehicle(id, climb_m)) return false;
  tracker_.pause(id);
  held_ = id;
  return true;
}

bool AdapterDrone::resume_motion() {
  const ActionId id = held_;
  held_ = kNoAction;
  if (id == kNoAction || !tracker_.running(id) || !failsafe_reason_.empty()) return false;
  tracker_.unpause(id);
  resume_vehicle(id);
  return true;
}

void AdapterDrone::after_for(ActionId id, double delay_s, std::function<void()> fn) {
  clear_action_timer(id);
  action_timers_[id] = loop_.after(delay_s, [this, id, fn = std::move(fn)] {
    action_timers_.erase(id);
    fn();
  });
}

void AdapterDrone::clear_action_timer(ActionId id) {
  auto it = action_timers_.find(id);
  if (it == action_timers_.end()) return;
  loop_.cancel(it->second);
  action_timers_.erase(it);
}

void AdapterDrone::end_all(const ActionEnd& e) {
  for (ActionId id : tracker_.running_ids()) {
    clear_action_timer(id);
    tracker_.end(id, e);
  }
}

}  // namespace eamos::mid
