#pragma once
// The outcome rules as book-keeping, so every adapter keeps them the same way: action ids,
// the one motion slot per drone (a new motion action preempts the old), delivery of each
// end exactly once through the event loop, and timeouts. The adapter decides what an action
// does to the vehicle; the tracker decides when and how it is reported.
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fleet/catalog.h"
#include "mid/drone_api.h"
#include "mid/event_loop.h"

namespace eamos::mid {

class ActionTracker {
 public:
  /// `on_timeout` is called when a running action passes its deadline, before it ends
  /// `failed`, so the adapter can stop what the vehicle is doing for it. `describe`, when
  /// given, says first where the vehicle stands against what the action waited for ("0.42 m
  /// across, 0.35 m below its goal, at 0.05 m/s"): it goes into the failure's reason.
  /// `distance_left`, when given, says how far (m) a running action's vehicle still has to
  /// go, NaN when it cannot tell: a deadline that comes while that shrinks is extended
  /// (begin(), mid/timeouts.h).
  ActionTracker(EventLoop& loop, std::function<void(ActionId)> on_timeout,
                std::function<std::string(ActionId)> describe = nullptr,
                std::function<double(ActionId)> distance_left = nullptr);
  /// Ends what still runs as `cancelled` ("drone shut down"): every end is reported once.
  ~ActionTracker();
  ActionTracker(const ActionTracker&) = delete;
  ActionTracker& operator=(const ActionTracker&) = delete;

  /// Registers a running action with a deadline `timeout_s` after now (infinity: none). A
  /// motion action takes the motion slot; the one holding it ends `preempted`. With a
  /// `closing_window_s` (0: none), the deadline moves on by that window each time the
  /// vehicle came kClosingMin_m nearer over the last one, up to `timeout_s` more in all.
  /// `vehicle_clock_rate` (vehicle seconds per mission second, below 1 for a vehicle that
  /// cannot keep up) is what `timeout_s` was stretched by: a timeout names both clocks.
  ActionId begin(const ActionRequest& request, fleet::ActionClass action_class,
                 EndCallback on_end, double timeout_s, double closing_window_s = 0.0,
                 double vehicle_clock_rate = 1.0);
  /// Registers an action that is not started: it ends `failed` at once with `why` (its
  /// failure set: refused, link_lost, …), reported through the loop like every other end.
  ActionId refuse(const ActionRequest& request, EndCallback on_end, ActionEnd why);
  /// Ends a running action; false (and nothing reported) when it is not running. For
  /// succeeded, preempted and cancelled ends; a failure goes through fail().
  bool end(ActionId id, Outcome outcome, std::string reason = "",
           std::optional<double> value = std::nullopt);
  /// Ends a running action `failed` for `why`, with the vehicle's own `detail`.
  bool fail(ActionId id, FailureReason why, std::string reason, std::string detail = "");
  /// Ends a running action as `e` says.
  bool end(ActionId id, ActionEnd e);

  /// Stops the clock of a running action's deadline (it is held for another drone); false
  /// when it is not running or already paused.
  bool pause(ActionId id);
  /// Starts it again where it stopped: the deadline moves on by the time paused.
  bool unpause(ActionId id);

  bool running(ActionId id) const { return actions_.count(id) != 0; }
  /// The running motion action; kNoAction when none.
  ActionId motion() const { return motion_; }
  /// Every running action, oldest first.
  std::vector<ActionId> running_ids() const;
  /// The request of a running action; nullptr when it is not running.
  const ActionRequest* request(ActionId id) const;
  /// Mission time a running action started; 0 when it is not running.
  double started_at(ActionId id) const;

 private:
  struct Running {
    ActionRequest request;
    fleet::ActionClass action_class;
    EndCallback on_end;
    double started_at;
    TimerId deadline;  ///< kNoTimer when the action has none
    double timeout_s = 0.0;
    double window_s = 0.0;      ///< closing window; 0 = the deadline stays where it is
    double granted_s = 0.0;     ///< time given beyond timeout_s while the vehicle closed in
    double window_from_m = 0.0; ///< distance left when the current window began (NaN: unknown)
    double clock_rate = 1.0;    ///< vehicle seconds per mission second timeout_s allowed for
    double due = 0.0;           ///< mission time the armed timer fires
    bool due_probe = false;     ///< ... and whether it starts a closing window
    bool paused = false;        ///< pause(): the deadline's clock stands still
    double paused_left = -1.0;  ///< paused: seconds that were left to `due`; -1 none armed
  };

  /// Arms the timer for a window's start (`probe`) or for the deadline itself.
  void arm(ActionId id, double delay_s, bool probe);
  void deadline_passed(ActionId id);
  void time_out(ActionId id);
  static std::string deadline_text(const Running& r);
  void report(EndCallback on_end, ActionEnd end);

  EventLoop& loop_;
  std::function<void(ActionId)> on_timeout_;
  std::function<std::string(ActionId)> describe_;
  std::function<double(ActionId)> distance_left_;
  ActionId next_id_ = 1;
  ActionId motion_ = kNoAction;
  std::map<ActionId, Running> actions_;  ///< ordered: ids grow with start order
};

}  // namespace eamos::mid
