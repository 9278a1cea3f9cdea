// ActionTracker: the outcome rules every adapter shares. Ends are reported exactly once and
// only through the loop; a motion action preempts the running one; deadlines fail actions.
#include "mid/action_tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mid/state_broker.h"

namespace eamos::mid {
namespace {

using fleet::ActionClass;

struct Ends {
  std::vector<std::pair<int, ActionEnd>> seen;  ///< (tag, end) in report order
  EndCallback tag(int t) {
    return [this, t](const ActionEnd& e) { seen.emplace_back(t, e); };
  }
};

TEST(ActionTracker, EndIsReportedThroughTheLoopNotInline) {
  EventLoop loop;
  ActionTracker tracker(loop, [](ActionId) {});
  Ends ends;
  ActionId id = tracker.begin({"TakePicture", {}}, ActionClass::payload, ends.tag(1), 1e9);
  EXPECT_TRUE(tracker.end(id, Outcome::succeeded));
  EXPECT_TRUE(ends.seen.empty());
  loop.run_until_idle();
  ASSERT_EQ(ends.seen.size(), 1u);
  EXPECT_EQ(ends.seen[0].second.outcome, Outcome::succeeded);
}

TEST(ActionTracker, EachActionEndsExactlyOnce) {
  EventLoop loop;
  ActionTracker tracker(loop, [](ActionId) {});
  Ends ends;
  ActionId id = tracker.begin({"FlyTo", {1, 2, 3}}, ActionClass::motion, ends.tag(1), 1e9);
  EXPECT_TRUE(tracker.end(id, Outcome::cancelled, "cancelled"));
  EXPECT_FALSE(tracker.end(id, Outcome::succeeded));
  EXPECT_FALSE(tracker.running(id));
  loop.run_until_idle();
  ASSERT_EQ(ends.seen.size(), 1u);
  EXPECT_EQ(ends.seen[0].second.outcome, Outcome::cancelled);
}

TEST(ActionTracker, NewMotionPreemptsTheRunningOne) {
  EventLoop loop;
  ActionTracker tracker(loop, [](ActionId) {});
  Ends ends;
  ActionId orbit = tracker.begin({"Orbit", {}}, ActionClass::motion, ends.tag(1), INFINITY);
  ActionId land = tracker.begin({"Land", {}}, ActionClass::motion, ends.tag(2), 30);
  EXPECT_FALSE(tracker.running(orbit));
  EXPECT_EQ(tracker.motion(), land);
  loop.run_until(1.0);
  ASSERT_EQ(ends.seen.size(), 1u);
  EXPECT_EQ(ends.seen[0].first, 1);
  EXPECT_EQ(ends.seen[0].second.outcome, Outcome::preempted);
  EXPECT_EQ(ends.seen[0].second.reason, "preempted by Land");
}

TEST(ActionTracker, PayloadAndSystemActionsDoNotPreemptMotion) {
  EventLoop loop;
  ActionTracker tracker(loop, [](ActionId) {});
  Ends ends;
  ActionId fly = tracker.begin({"FlyTo", {1, 2, 3}}, ActionClass::motion, ends.tag(1), 1e9);
  tracker.begin({"TakePicture", {}}, ActionClass::payload, ends.tag(2), 1e9);
  tracker.begin({"Sensor1", {}}, ActionClass::payload, ends.tag(3), 1e9);
  EXPECT_TRUE(tracker.running(fly));
  EXPECT_EQ(tracker.motion(), fly);
  EXPECT_EQ(tracker.running_ids().size(), 3u);
}

TEST(ActionTracker, DeadlineStopsThenFailsTheAction) {
  EventLoop loop;
  std::vector<ActionId> stopped;
  ActionTracker tracker(loop, [&](ActionId id) { stopped.push_back(id); });
  Ends ends;
  ActionId id = tracker.begin({"FlyTo", {1, 2, 3}}, ActionClass::motion, ends.tag(1), 2.5);
  loop.run_until_idle();
  EXPECT_EQ(stopped, std::vector<ActionId>{id});
  ASSERT_EQ(ends.seen.size(), 1u);
  EXPECT_EQ(ends.seen[0].second.outcome, Outcome::failed);
  EXPECT_EQ(ends.seen[0].second.reason, "timed out after 2.5 s");
  EXPECT_EQ(ends.seen[0].second.failure, FailureReason::timed_out);
  EXPECT_EQ(ends.seen[0].second.detail, "deadline 2.5 s after start");
  EXPECT_DOUBLE_EQ(loop.now(), 2.5);
  EXPECT_EQ(tracker.motion(), kNoAction);
}

TEST(ActionTracker, ADeadlineStretchedForASlowVehicleClockNamesBothClocks) {
  EventLoop loop;
  ActionTracker tracker(loop, [](ActionId) {});
  Ends ends;
  // 2.0 s of a vehicle whose clock runs at 0.8 of mission time: 2.5 mission seconds.
  tracker.begin({"FlyTo", {1, 2, 3}}, ActionClass::motion, ends.tag(1), 2.5, 0.0, 0.8);
  loop.run_until_idle();
  ASSERT_EQ(ends.seen.size(), 1u);
  EXPECT_EQ(ends.seen[0].second.reason, "timed out after 2.5 s");
  EXPECT_EQ(ends.seen[0].second.detail,
            "deadline 2.0 s of the vehicle's clock after start (2.5 s of mission time: the vehicle's clock ran "
            "at 0.80 of it)");
  EXPECT_DOUBLE_EQ(loop.now(), 2.5);
}

TEST(ActionTracker, AVehicleClockWithinHalfAPercentIsMissionTime) {
  EventLoop loop;
  ActionTracker tracker(loop, [](ActionId) {});
  Ends ends;
  tracker.begin({"FlyTo", {1, 2, 3}}, ActionClass::motion, ends.tag(1), 2.0, 0.0, 0.996);
  loop.run_until_idle();
  ASSERT_EQ(ends.seen.size(), 1u);
  EXPECT_EQ(ends.seen[0].second.detail, "deadline 2.0 s after start");
}

TEST(ActionTracker, ATimeoutSaysWhereTheVehicleStandsWhenTheAdapterKnows) {
  EventLoop loop;
  std::vector<std::string> order;
  ActionTracker tracker(
      loop, [&](ActionId) { order.push_back("stopped"); },
      [&](ActionId) {
        order.push_back("described");
        return std::string("0.40 m across");
      });
  Ends ends;
  tracker.begin({"FlyTo", {1, 2, 3}}, ActionClass::motion, ends.tag(1), 2.5);
  loop.run_until_idle();
  ASSERT_EQ(ends.seen.size(), 1u);
  EXPECT_EQ(ends.seen[0].second.reason, "timed out after 2.5 s (0.40 m across)");
  // Described before the stop, which clears the goal the description measures from.
  EXPECT_EQ(order, (std::vector<std::string>{"described", "stopped"}));
}

TEST(ActionTracker, EndedActionLeavesNoDeadlineBehind) {
  EventLoop loop;
  int stops = 0;
  ActionTracker tracker(loop, [&](ActionId) { ++stops; });
  Ends ends;
  ActionId id = tracker.begin({"Hover", {5}}, ActionClass::motion, ends.tag(1), 17.5);
  tracker.end(id, Outcome::succeeded);
  loop.run_until_idle();
  EXPECT_EQ(stops, 0);
  EXPECT_EQ(loop.now(), 0.0);  // nothing was left scheduled at 17.5
}

TEST(ActionTracker, RefusedActionEndsFailedThroughTheLoop) {
  EventLoop loop;
  ActionTracker tracker(loop, [](ActionId) {});
  Ends ends;
  ActionId id = tracker.refuse({"Takeoff", {3}}, ends.tag(1), {.reason = "disarmed: arm before Takeoff"});
  EXPECT_NE(id, kNoAction);
  EXPECT_FALSE(tracker.running(id));
  EXPECT_TRUE(ends.seen.empty());
  loop.run_until_idle();
  ASSERT_EQ(ends.seen.size(), 1u);
  EXPECT_EQ(ends.seen[0].second.outcome, Outcome::failed);
  EXPECT_EQ(ends.seen[0].second.reason, "disarmed: arm before Takeoff");
  EXPECT_EQ(ends.seen[0].second.failure, FailureReason::refused);  // a refusal unless it says otherwise
}

TEST(ActionTracker, AFailureCarriesItsKindAndDetailAndOnlyAFailureDoes) {
  EventLoop loop;
  ActionTracker tracker(loop, [](ActionId) {});
  Ends ends;
  ActionId lost = tracker.begin({"Hover", {}}, ActionClass::motion, ends.tag(1), 1e9);
  ActionId picture = tracker.begin({"TakePicture", {}}, ActionClass::payload, ends.tag(2), 1e9);
  ActionId read = tracker.begin({"Sensor1", {}}, ActionClass::payload, ends.tag(3), 1e9);
  EXPECT_TRUE(tracker.fail(lost, FailureReason::link_lost, "link lost", "no HEARTBEAT"));
  // A failure that names no kind is still one of the five, never "none".
  EXPECT_TRUE(tracker.end(picture, ActionEnd{.outcome = Outcome::failed, .reason = "camera"}));
  EXPECT_TRUE(tracker.end(read, ActionEnd{.outcome = Outcome::succeeded, .failure = FailureReason::refused}));
  loop.run_until_idle();
  ASSERT_EQ(ends.seen.size(), 3u);
  EXPECT_EQ(ends.seen[0].second.failure, FailureReason::link_lost);
  EXPECT_EQ(ends.seen[0].second.detail, "no HEARTBEAT");
  EXPECT_EQ(ends.seen[1].second.failure, FailureReason::vehicle_fault);
  EXPECT_EQ(ends.seen[2].second.failure, FailureReason::none);
  EXPECT_STREQ(failure_reason_name(FailureReason::pilot_took_over), "pilot_took_over");
  EXPECT_STREQ(failure_reason_name(FailureReason::none), "");
}

TEST(ActionTracker, ShutdownCancelsWhatStillRuns) {
  EventLoop loop;
  Ends ends;
  {
    ActionTracker tracker(loop, [](ActionId) {});
    tracker.begin({"Orbit", {}}, ActionClass::motion, ends.tag(1), INFINITY);
  }
  loop.run_until_idle();
  ASSERT_EQ(ends.seen.size(), 1u);
  EXPECT_EQ(ends.seen[0].second.outcome, Outcome::cancelled);
}

TEST(ActionTracker, OutcomesHaveNames) {
  EXPECT_STREQ(outcome_name(Outcome::succeeded), "succeeded");
  EXPECT_STREQ(outcome_name(Outcome::preempted), "preempted");
  EXPECT_STREQ(outcome_name(Outcome::cancelled), "cancelled");
  EXPECT_STREQ(outcome_name(Outcome::failed), "failed");
}

TEST(StateBroker, PublishesToSubscribersInOrderAndSurvivesUnsubscribeInCallback) {
  StateBroker broker;
  std::vector<int> calls;
  SubscriptionId first = 0;
  first = broker.subscribe([&](const DroneState&) {
    calls.push_back(1);
    broker.unsubscribe(first);
  });
  broker.subscribe([&](const DroneState& s) { calls.push_back(static_cast<int>(s.t)); });
  DroneState s;
  s.t = 7;
  broker.publish(s);
  broker.publish(s);
  EXPECT_EQ(calls, (std::vector<int>{1, 7, 7}));
}


// A tracker whose vehicle has `left(t)` metres to go at mission time t.
struct Closing {
  EventLoop loop;
  std::function<double(double)> left;
  ActionTracker tracker{loop, [](ActionId) {}, nullptr, [this](ActionId) { return left(loop.now()); }};
  Ends ends;

  /// Starts a motion with this deadline and closing window (0: none), runs until it ends,
  /// and returns its one end.
  ActionEnd run(double timeout_s, double window_s) {
    tracker.begin({"FlyTo", {1, 2, 3}}, ActionClass::motion, ends.tag(1), timeout_s, window_s);
    loop.run_until_idle();
    EXPECT_EQ(ends.seen.size(), 1u);
    return ends.seen.empty() ? ActionEnd{} : ends.seen[0].second;
  }
};

TEST(ActionTracker, ADeadlineMovesOnWhileTheVehicleStillClosesInAndFailsOnceItStalls) {
  Closing c;
  c.left = [](double t) { return 10.0 - 0.5 * std::min(t, 7.5); };  // 0.5 m/s, stalls at 7.5 s
  ActionEnd e = c.run(5.0, 1.0);
  // Windows 4-5, 5-6, 6-7 and 7-8 s each closed in by 0.25 m or more; 8-9 s by nothing.
  EXPECT_DOUBLE_EQ(c.loop.now(), 9.0);
  EXPECT_EQ(e.failure, FailureReason::timed_out);
  EXPECT_EQ(e.reason, "timed out after 9.0 s, 4.0 s of them given while it still closed in on its goal");
  EXPECT_EQ(e.detail, "deadline 5.0 s after start, extended by 4.0 s");
}

TEST(ActionTracker, AVehicleThatDoesNotCloseInFailsAtItsDeadline) {
  Closing c;
  c.left = [](double t) { return 3.0 - 0.05 * t; };  // 0.05 m a window: less than kClosingMin_m
  EXPECT_EQ(c.run(2.5, 1.0).reason, "timed out after 2.5 s");
  EXPECT_DOUBLE_EQ(c.loop.now(), 2.5);
}

TEST(ActionTracker, ACrawlingVehicleGetsItsDeadlineAgainAtMost) {
  Closing c;
  c.left = [](double t) { return 100.0 - t; };  // never arrives
  EXPECT_EQ(c.run(3.0, 1.0).detail, "deadline 3.0 s after start, extended by 3.0 s");
  EXPECT_DOUBLE_EQ(c.loop.now(), 6.0);
}

TEST(ActionTracker, WithoutAWindowOrADistanceTheDeadlineStaysWhereItWas) {
  Closing c;
  c.left = [](double t) { return 100.0 - t; };
  EXPECT_EQ(c.run(3.0, 0.0).reason, "timed out after 3.0 s");  // no window
  EXPECT_DOUBLE_EQ(c.loop.now(), 3.0);
  Closing unknown;
  unknown.left = [](double) { return std::nan(""); };  // the adapter cannot tell
  EXPECT_EQ(unknown.run(3.0, 1.0).reason, "timed out after 3.0 s");
  EXPECT_DOUBLE_EQ(unknown.loop.now(), 3.0);
}

TEST(ActionTracker, AnActionThatEndsDuringAnExtensionEndsOnce) {
  Closing c;
  c.left = [](double t) { return 10.0 - t; };
  ActionId id = c.tracker.begin({"FlyTo", {1, 2, 3}}, ActionClass::motion, c.ends.tag(1), 2.0, 1.0);
  c.loop.run_until(2.5);  // extended once at 2 s
  EXPECT_TRUE(c.tracker.running(id));
  EXPECT_TRUE(c.tracker.end(id, Outcome::succeeded));
  c.loop.run_until_idle();
  ASSERT_EQ(c.ends.seen.size(), 1u);
  EXPECT_EQ(c.ends.seen[0].second.outcome, Outcome::succeeded);
}

}  // namespace
}  // namespace eamos::mid
