#pragma once
// What every adapter's drone does the same way around its vehicle: starting an action (the
// failsafe and availability checks, the catalog check, the uniform refusals, the deadline,
// the motion slot), cancelling one, and the per-action timers. The adapter says only what
// its vehicle does: why it refuses beyond the uniform rules, how long an action may take,
// how each class of action starts and how a running one stops. One place, so the simulator
// and the MAVLink adapter cannot drift apart in what the DEX sees.
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>

#include "fleet/catalog.h"
#include "mid/action_tracker.h"
#include "mid/drone_api.h"
#include "mid/event_loop.h"
#include "mid/requests.h"

namespace eamos::mid {

class AdapterDrone : public Drone {
 public:
  AdapterDrone(EventLoop& loop, fleet::DroneType type);
  ~AdapterDrone() override;

  /// Refused (ends `failed` at once) in failsafe, when unavailable(), when the catalog or
  /// refusal() says no; else registered with the tracker and handed to start_<class>().
  ActionId start(const ActionRequest& request, EndCallback on_end) final;
  /// Stops the vehicle's part (stop_action) and ends the action `cancelled`.
  bool cancel(ActionId id) final;
  /// Give way (drone_api.h): the deadline is paused here, the vehicle held by hold_vehicle().
  bool hold_motion(double climb_m) final;
  bool resume_motion() final;
  double motion_distance_left() const final;
  std::optional<fleet::Vec3> motion_goal() const final;
  bool motion_held() const final { return held_ != kNoAction && tracker_.running(held_); }
  void set_fault_sink(std::function<void(const ActionEnd&)> sink) final { fault_sink_ = std::move(sink); }

 protected:
  /// Why the vehicle can take no action at all now (its link is lost, say), as the end to
  /// report; empty when it can.
  virtual std::optional<ActionEnd> unavailable() const { return std::nullopt; }
  /// Why this drone refuses `r` (the uniform rules, mid/requests.h, plus its own); "" = start.
  virtual std::string refusal(const ActionRequest& r, const fleet::ActionSpec& spec) const = 0;
  /// The deadline of `r` in mission seconds (infinity: none).
  virtual double timeout_for(const ActionRequest& r) const = 0;
  virtual void start_system(ActionId id, const ActionRequest& r) = 0;
  virtual void start_payload(ActionId id, const ActionRequest& r) = 0;
  virtual void start_motion(ActionId id, const ActionRequest& r) = 0;
  /// After every start() that registered an action (the simulator schedules its steps).
  virtual void started() {}
  /// What cancel() and a timeout do to the vehicle for a running action (its timer is
  /// already cleared); the action's end is reported by the caller.
  virtual void stop_action(ActionId id) = 0;
  /// Stops the vehicle for running motion `id` where it can stop, `climb_m` higher, keeping
  /// the motion's goal for resume_vehicle(); false when this vehicle cannot hold it.
  virtual bool hold_vehicle(ActionId, double /*climb_m*/) { return false; }
  /// Flies the held motion `id` on to its goal.
  virtual void resume_vehicle(ActionId) {}

  /// Where the vehicle stands against what a running action waits for, said when it times
  /// out ("" when there is nothing to say).
  virtual std::string timeout_detail(ActionId) const { return ""; }
  /// How far (m) the vehicle still has to go for a running action, NaN when the adapter
  /// cannot tell; with closing_window_s(), a deadline that comes while it shrinks moves on
  /// (mid/timeouts.h).
  virtual double distance_left(ActionId) const { return std::numeric_limits<double>::quiet_NaN(); }
  /// Where the vehicle goes for running motion `id` (motion_goal()); empty when it cannot tell.
  virtual std::optional<fleet::Vec3> goal_of(ActionId) const { return std::nullopt; }
  /// The closing window of `r`'s deadline in mission seconds; 0 (the default) keeps every
  /// deadline where timeout_for() put it.
  virtual double closing_window_s(const ActionRequest&) const { return 0.0; }
  /// Vehicle seconds per mission second that timeout_for() and closing_window_s() allowed
  /// for (1: the vehicle keeps mission time, as the simulator does). A timeout says it, so a
  /// deadline stretched for a slow vehicle clock still reads in the fleet file's seconds.
  virtual double deadline_clock_rate() const { return 1.0; }

  /// The site's rules this drone keeps in flight (fleet::SiteLimits) and the failsafe it flies
  /// when it finds itself outside its geofence; the adapter's constructor gives them.
  void keep_site(const fleet::DroneSettings& s);
  /// Every state the adapter publishes passes here first. Outside the geofence (armed, in the
  /// air, no failsafe yet) the drone fails over at the same instant: every running action
  /// ends `failed` (vehicle_fault) and failsafe() is commanded, and only then, through the
  /// loop, are the ends and the fault reported (the fault sink, when no action ran).
  void watch_site(const DroneState& s);
  bool watches_site() const { return fence_.has_value(); }

  /// Runs `fn` after `delay_s` for a running action; cleared when the action stops.
  void after_for(ActionId id, double delay_s, std::function<void()> fn);
  void clear_action_timer(ActionId id);
  /// From now on every start() is refused with `reason` ("failsafe: land").
  void refuse_from_now(std::string reason) { failsafe_reason_ = std::move(reason); }
  /// Ends every running action as `e` says (timers cleared, no stop_action).
  void end_all(const ActionEnd& e);

  EventLoop& loop_;
  fleet::DroneType type_;
  ActionTracker tracker_;
  std::string failsafe_reason_;  ///< "" = no failsafe; otherwise why new actions are refused

 private:
  std::map<ActionId, TimerId> action_timers_;  ///< ends of payload, system, Hover(s), …
  ActionId held_ = kNoAction;  ///< the motion held by hold_motion(), while it runs
  void left_fence(const std::string& where);

  std::string name_;                      ///< for the fault's words
  std::optional<fleet::Geofence> fence_;  ///< none: nothing to watch
  fleet::Failsafe fence_failsafe_ = fleet::Failsafe::land;
  bool breach_pending_ = false;           ///< a breach is being acted on this instant
  std::function<void(const ActionEnd&)> fault_sink_;
};

}  // namespace eamos::mid
