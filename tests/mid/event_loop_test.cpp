// EventLoop: the executor's clock. Virtual time jumps from event to event; equal times run
// in scheduling order; real time waits on a (here fake) wall clock scaled by the speed.
#include "mid/event_loop.h"

#include <gtest/gtest.h>

#include <functional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "diag/log.h"

namespace eamos::mid {
namespace {

TEST(EventLoop, RunsCallbacksInTimeOrder) {
  EventLoop loop;
  std::vector<double> seen;
  loop.at(3.0, [&] { seen.push_back(loop.now()); });
  loop.at(1.0, [&] { seen.push_back(loop.now()); });
  loop.after(2.0, [&] { seen.push_back(loop.now()); });
  EXPECT_EQ(loop.run_until_idle(), 3u);
  EXPECT_EQ(seen, (std::vector<double>{1.0, 2.0, 3.0}));
  EXPECT_DOUBLE_EQ(loop.now(), 3.0);
}

TEST(EventLoop, EqualTimesRunInSchedulingOrder) {
  EventLoop loop;
  std::string order;
  loop.at(1.0, [&] { order += 'a'; });
  loop.at(1.0, [&] { order += 'b'; });
  loop.at(0.5, [&] {
    order += 'c';
    loop.at(1.0, [&] { order += 'd'; });  // scheduled later, so after a and b
  });
  loop.run_until_idle();
  EXPECT_EQ(order, "cabd");
}

// Many timers at few distinct times (a fleet's motion steps share their instants), some
// scheduled from callbacks and some cancelled: each runs at its time, equal times in the
// order they were scheduled, the cancelled never.
TEST(EventLoop, ThousandsOfTimersRunInTimeThenSchedulingOrder) {
  EventLoop loop;
  std::uint64_t seed = 7;
  auto below = [&seed](int n) {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<int>((seed >> 33) % static_cast<std::uint64_t>(n));
  };
  struct Ran {
    double t;
    int order;  ///< when it was scheduled
  };
  std::vector<Ran> ran;
  int scheduled = 0;
  std::function<void(double)> schedule = [&](double t) {
    const int order = scheduled++;
    TimerId id = loop.at(t, [&, t, order] {
      ran.push_back({loop.now(), order});
      EXPECT_EQ(loop.now(), t);
      if (scheduled < 20000) schedule(loop.now() + 0.05 * below(5));
    });
    if (below(4) == 0) loop.cancel(id);
  };
  for (int i = 0; i < 5000; ++i) schedule(0.05 * below(40));
  loop.run_until_idle();
  ASSERT_GT(ran.size(), 10000u);
  for (std::size_t i = 1; i < ran.size(); ++i) {
    ASSERT_LE(ran[i - 1].t, ran[i].t) << i;
    if (ran[i - 1].t == ran[i].t) {
      ASSERT_LT(ran[i - 1].order, ran[i].order) << i;
    }
  }
}

// A run that schedules a timeout for every action and cancels it when the action ends (a
// long mission, thousands of actions) keeps in its queue what is pending, not every timer it
// ever cancelled.
TEST(EventLoop, CancelledTimersDoNotPileUpInTheQueue) {
  EventLoop loop;
  TimerId keep = loop.at(1e6, [] {});
  for (int i = 0; i < 100000; ++i) loop.cancel(loop.at(1000.0 + i, [] {}));
  EXPECT_EQ(loop.size(), 1u);
  EXPECT_LT(loop.queued(), 2000u);
  EXPECT_TRUE(loop.pending(keep));
  EXPECT_EQ(loop.run_until_idle(), 1u);
}

// Cancelling so many timers from inside a callback that the queue compacts, while the
// callbacks of that instant are half run, leaves the rest of the instant (and one scheduled
// for it afterwards) to run in scheduling order.
TEST(EventLoop, CompactingInTheMiddleOfAnInstantKeepsTheRestInOrder) {
  EventLoop loop;
  std::vector<TimerId> doomed;
  for (int i = 0; i < 3000; ++i) doomed.push_back(loop.at(2.0 + i, [] { ADD_FAILURE() << "cancelled"; }));
  std::vector<int> ran;
  for (int i = 0; i < 10; ++i)
    loop.at(1.0, [&, i] {
      ran.push_back(i);
      if (i == 4)
        for (TimerId t : doomed) loop.cancel(t);
      if (i == 5) loop.at(1.0, [&] { ran.push_back(10); });
    });
  EXPECT_EQ(loop.run_until_idle(), 11u);
  EXPECT_EQ(ran, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
  EXPECT_EQ(loop.queued(), 0u);
}

// A thousand drones stepping at the same instants fill one bucket each instant; a bucket used
// for such an instant and then for a timeout of its own must not keep the thousand entries'
// room, or the queue's memory grows with the drones times the timers.
TEST(EventLoop, ABucketThatHeldAThousandTimersDoesNotKeepTheirRoom) {
  EventLoop loop;
  for (int round = 0; round < 50; ++round) {
    for (int d = 0; d < 1000; ++d) loop.at(round + 1.0, [] {});
    for (int i = 0; i < 20; ++i) loop.at(round + 1.0 + 0.001 * (i + 1), [] {});  // timeouts
  }
  std::size_t most_queued = 0;
  loop.at(0.5, [&] { most_queued = loop.queued(); });
  loop.run_until_idle();
  EXPECT_EQ(most_queued, 51000u);
  EXPECT_LT(loop.queue_room(), 5000u) << "the 50 instants of 1,000 steps each kept their room";
}

// Two cascades of zero-delay callbacks, each callback scheduling the next of its cascade at
// the same instant (so the instant never runs out of callbacks until both end): the queue
// holds what is still to run, not the million callbacks the instant has run.
TEST(EventLoop, AnInstantThatKeepsSchedulingItselfHoldsOnlyWhatIsStillToRun) {
  EventLoop loop;
  int left = 1000000;
  std::size_t most_room = 0;
  std::function<void()> next = [&] {
    most_room = std::max(most_room, loop.queue_room());
    if (--left > 0) loop.after(0.0, next);
  };
  loop.at(1.0, next);
  loop.at(1.0, next);
  loop.run_until_idle();
  EXPECT_LE(left, 0);
  EXPECT_LT(most_room, 10000u);
}

// The schedule a callback builds depends only on what ran before it, so two loops fed the
// same program produce the same trace: the basis of deterministic simulated missions.
TEST(EventLoop, EventLoopRunsSameScheduleIdentically) {
  auto trace_of = [] {
    EventLoop loop;
    std::vector<std::string> trace;
    std::function<void(int)> tick = [&](int n) {
      trace.push_back(std::to_string(loop.now()) + ":" + std::to_string(n));
      if (n < 50) {
        loop.after(0.1 * (n % 4), [&, n] { tick(n + 1); });
        loop.after(0.1 * (n % 3), [&, n] { trace.push_back("side" + std::to_string(n)); });
      }
    };
    loop.at(0.0, [&] { tick(0); });
    loop.run_until_idle();
    return trace;
  };
  std::vector<std::string> first = trace_of();
  EXPECT_GT(first.size(), 100u);
  EXPECT_EQ(first, trace_of());
}

// A callback that throws (a bug, a bad sample that got through) must not end the loop of
// a process whose drone is in the air: the handler hears of it and the loop goes on.
TEST(EventLoop, ThrowingCallbackReachesTheErrorHandlerAndTheLoopGoesOn) {
  EventLoop loop;
  std::vector<std::string> errors;
  loop.on_callback_error([&](const std::string& what) { errors.push_back(what); });
  std::string order;
  loop.at(1.0, [&] {
    order += 'a';
    throw std::out_of_range("vector::_M_range_check");
  });
  loop.at(1.0, [&] { throw 42; });
  loop.at(2.0, [&] { order += 'b'; });
  EXPECT_EQ(loop.run_until_idle(), 3u);
  EXPECT_EQ(order, "ab");
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0], "vector::_M_range_check");
  EXPECT_EQ(errors[1], "an exception that is not a std::exception");
}

TEST(EventLoop, ThrowingErrorHandlerDoesNotEndTheLoopEither) {
  EventLoop loop;
  loop.on_callback_error([](const std::string&) { throw std::runtime_error("handler"); });
  bool later = false;
  loop.at(1.0, [] { throw std::runtime_error("callback"); });
  loop.at(2.0, [&] { later = true; });
  loop.run_until_idle();
  EXPECT_TRUE(later);
}

// Without a handler (or when the handler throws) the error goes to the log, as an error of
// the mid layer, and the loop goes on.
TEST(EventLoop, AnErrorNobodyHandlesIsLoggedAsAnErrorOfTheMidLayer) {
  std::vector<std::string> lines;
  diag::LogSink saved = diag::set_log_sink([&](std::string_view line) { lines.emplace_back(line); });
  EventLoop loop;
  loop.at(1.0, [] { throw std::runtime_error("bad sample"); });
  loop.run_until_idle();
  EventLoop second;
  second.on_callback_error([](const std::string&) { throw std::runtime_error("handler"); });
  second.at(1.0, [] { throw std::runtime_error("callback"); });
  second.run_until_idle();
  diag::set_log_sink(std::move(saved));
  EXPECT_EQ(lines, (std::vector<std::string>{
                       "eamos mid: error: error in an event callback: bad sample",
                       "eamos mid: error: error while handling an error in an event callback"}));
}

TEST(EventLoop, CancelledTimerNeverRuns) {
  EventLoop loop;
  bool ran = false;
  TimerId id = loop.after(1.0, [&] { ran = true; });
  EXPECT_TRUE(loop.pending(id));
  EXPECT_TRUE(loop.cancel(id));
  EXPECT_FALSE(loop.cancel(id));
  EXPECT_EQ(loop.size(), 0u);
  EXPECT_EQ(loop.run_until_idle(), 0u);
  EXPECT_FALSE(ran);
}

TEST(EventLoop, CallbackCanCancelALaterTimer) {
  EventLoop loop;
  bool ran = false;
  TimerId later = loop.at(2.0, [&] { ran = true; });
  loop.at(1.0, [&] { loop.cancel(later); });
  loop.run_until_idle();
  EXPECT_FALSE(ran);
}

TEST(EventLoop, RunUntilRunsDueEventsAndSetsNow) {
  EventLoop loop;
  int ran = 0;
  loop.at(1.0, [&] { ++ran; });
  loop.at(2.0, [&] { ++ran; });
  loop.at(5.0, [&] { ++ran; });
  EXPECT_EQ(loop.run_until(2.0), 2u);  // an event exactly at the bound runs
  EXPECT_DOUBLE_EQ(loop.now(), 2.0);
  EXPECT_EQ(loop.run_until(4.0), 0u);
  EXPECT_DOUBLE_EQ(loop.now(), 4.0);
  EXPECT_EQ(loop.size(), 1u);
}

TEST(EventLoop, PastTimeRunsNow) {
  EventLoop loop;
  loop.run_until(10.0);
  double when = -1;
  loop.at(3.0, [&] { when = loop.now(); });
  loop.run_until_idle();
  EXPECT_DOUBLE_EQ(when, 10.0);
}

TEST(EventLoop, NonFiniteTimeSchedulesNothing) {
  EventLoop loop;
  EXPECT_EQ(loop.at(std::numeric_limits<double>::infinity(), [] {}), kNoTimer);
  EXPECT_EQ(loop.after(std::numeric_limits<double>::quiet_NaN(), [] {}), kNoTimer);
  EXPECT_EQ(loop.size(), 0u);
}

TEST(EventLoop, StopReturnsAfterTheCurrentCallback) {
  EventLoop loop;
  int ran = 0;
  loop.at(1.0, [&] { ++ran; loop.stop(); });
  loop.at(2.0, [&] { ++ran; });
  EXPECT_EQ(loop.run_until(10.0), 1u);
  EXPECT_DOUBLE_EQ(loop.now(), 1.0);  // stopped: time stays at the last event
  EXPECT_EQ(loop.run_until_idle(), 1u);
  EXPECT_EQ(ran, 2);
  EXPECT_EQ(loop.events_run(), 2u);
}

// A fake wall clock: sleeping just moves its time, so real-time mode is tested without waiting.
class FakeWall final : public WallClock {
 public:
  double now_s() override { return t; }
  void sleep_until_s(double until) override {
    sleeps.push_back(until);
    t = until;
  }
  double t = 100.0;
  std::vector<double> sleeps;
};

TEST(EventLoop, RealTimeWaitsUntilScaledWallTime) {
  FakeWall wall;
  EventLoop loop({ClockMode::real_time, 2.0, &wall});
  loop.at(1.0, [] {});
  loop.at(3.0, [] {});
  loop.run_until_idle();
  // Twice as fast as the wall: mission second 1 at wall +0.5, second 3 at wall +1.5.
  EXPECT_EQ(wall.sleeps, (std::vector<double>{100.5, 101.5}));
}

TEST(EventLoop, RealTimeDoesNotWaitForLateEvents) {
  FakeWall wall;
  EventLoop loop({ClockMode::real_time, 1.0, &wall});
  loop.at(1.0, [&] { wall.t += 5.0; });  // a slow callback: the next event is already due
  loop.at(2.0, [] {});
  loop.run_until_idle();
  EXPECT_EQ(wall.sleeps, (std::vector<double>{101.0}));
}

// A callback that keeps the loop busy past the next one's wall time: that one runs late, by
// the busy wall time times the speed in mission time, and max_lag says so. On time, no lag.
TEST(EventLoop, MaxLagIsTheMostMissionTimeACallbackRanLate) {
  FakeWall wall;
  EventLoop loop({ClockMode::real_time, 10.0, &wall});
  loop.at(1.0, [] {});
  loop.at(2.0, [] {});
  loop.run_until_idle();
  EXPECT_NEAR(loop.max_lag(), 0.0, 1e-9);  // each ran at its time (up to rounding)
  loop.at(3.0, [&] { wall.t += 0.25; });  // busy for a quarter of a wall second
  loop.at(4.0, [] {});                    // due 0.1 wall s after 3.0: runs 0.15 wall s late
  loop.at(9.0, [] {});
  loop.run_until_idle();
  EXPECT_NEAR(loop.max_lag(), 1.5, 1e-9);  // 0.15 wall s at ten times the wall
  EventLoop virtual_time;
  virtual_time.at(1.0, [] {});
  virtual_time.run_until_idle();
  EXPECT_EQ(virtual_time.max_lag(), 0.0);
}

// A process stopped (SIGSTOP) for longer than the bound: the stall handler runs before any
// overdue callback, at the mission time the wall clock shows (not back-dated), and what it
// cancels never runs. Before on_stall the overdue timer ran 4.75 wall seconds late.
TEST(EventLoop, StallLongerThanTheBoundRunsTheHandlerFirstAtTheMissionTimeOfItsEnd) {
  FakeWall wall;
  EventLoop loop({ClockMode::real_time, 2.0, &wall});
  std::vector<std::string> order;
  double stalled = 0.0, handler_at = -1.0;
  TimerId overdue = kNoTimer;
  loop.at(1.0, [&] { wall.t += 5.0; });  // the process stood still for 5 wall seconds here
  overdue = loop.at(1.5, [&] { order.push_back("overdue action"); });
  loop.at(1.6, [&] { order.push_back("at " + std::to_string(loop.now())); });
  loop.on_stall(1.0, [&](double s) {
    stalled = s;
    handler_at = loop.now();
    order.push_back("stall");
    loop.cancel(overdue);
  });
  loop.run_until_idle();
  // Mission 1.5 was due at wall 100.75; the loop looked again at 105.5.
  EXPECT_DOUBLE_EQ(stalled, 4.75);
  EXPECT_DOUBLE_EQ(handler_at, 11.0);  // wall 105.5 is mission (105.5 - 100) * 2
  // What was overdue and not cancelled runs after the handler, at its mission time.
  EXPECT_EQ(order, (std::vector<std::string>{"stall", "at " + std::to_string(11.0)}));
}

TEST(EventLoop, StallShorterThanTheBoundIsNoStall) {
  FakeWall wall;
  EventLoop loop({ClockMode::real_time, 1.0, &wall});
  bool stalled = false, ran = false;
  loop.at(1.0, [&] { wall.t += 0.5; });
  loop.at(1.2, [&] { ran = true; });
  loop.on_stall(1.0, [&](double) { stalled = true; });
  loop.run_until_idle();
  EXPECT_FALSE(stalled);
  EXPECT_TRUE(ran);
}

// A DEX whose START came late catches up from the agreed mission time 0: many callbacks
// overdue at once, but the loop was not stalled while running.
TEST(EventLoop, CatchingUpALateStartIsNoStall) {
  FakeWall wall;
  EventLoop loop({ClockMode::real_time, 1.0, &wall});
  loop.set_wall_origin(95.0);  // mission time 0 was 5 wall seconds ago
  bool stalled = false;
  int ran = 0;
  for (int i = 0; i < 10; ++i) loop.at(i * 0.5, [&] { ++ran; });
  loop.on_stall(1.0, [&](double) { stalled = true; });
  loop.run_until_idle();
  EXPECT_FALSE(stalled);
  EXPECT_EQ(ran, 10);
}

TEST(EventLoop, DeferredCallbackRunsAfterEverythingAlreadyDueOnVirtualTime) {
  EventLoop loop;
  std::vector<int> order;
  loop.at(0.0, [&] {
    loop.defer([&] { order.push_back(2); });
    loop.at(0.0, [&] { order.push_back(3); });
  });
  loop.at(0.0, [&] { order.push_back(1); });
  loop.at(1.0, [&] { order.push_back(4); });
  loop.run_until_idle();
  EXPECT_EQ(order, (std::vector<int>{1, 2, 3, 4}));
}

// A callback that keeps deferring itself (a loop iteration taking no time) lets mission
// time follow the wall on real time, so a later timer (the time limit) still comes.
TEST(EventLoop, DeferredCallbackOnRealTimeRunsAtTheWallsMissionTimeSoLaterTimersComeDue) {
  FakeWall wall;
  EventLoop loop({ClockMode::real_time, 1.0, &wall});
  bool limit = false;
  int spins = 0;
  std::function<void()> spin = [&] {
    ++spins;
    wall.t += 0.25;  // the work of one iteration
    if (!limit) loop.defer(spin);
  };
  loop.at(0.0, spin);
  loop.at(2.0, [&] { limit = true; });
  loop.run_until_idle();
  EXPECT_TRUE(limit);
  EXPECT_EQ(spins, 9);  // at 0, 0.25, … 2.0: the last deferred after the limit ran
}

TEST(EventLoop, VirtualTimeNeverTouchesTheWallClock) {
  FakeWall wall;
  EventLoop loop({ClockMode::virtual_time, 1.0, &wall});
  loop.at(3600.0, [] {});
  loop.run_until(7200.0);
  EXPECT_TRUE(wall.sleeps.empty());
  EXPECT_DOUBLE_EQ(loop.now(), 7200.0);
}

TEST(EventLoop, PostedCallbackRunsOnTheLoopAtTheCurrentTime) {
  EventLoop loop;
  std::vector<double> at;
  loop.at(2.0, [&] { loop.post([&] { at.push_back(loop.now()); }); });
  loop.at(5.0, [&] { at.push_back(loop.now()); });
  loop.run_until_idle();
  EXPECT_EQ(at, (std::vector<double>{2.0, 5.0}));
}

// Posted while the loop runs behind the wall clock, a callback gets the wall's mission time;
// the loop stops before it runs, and the next run anchors its clock at the loop's own time.
// What is posted then still runs after it: input runs in the order it came (a vehicle's
// frames in the order the vehicle sent them).
TEST(EventLoop, PostedCallbacksRunInTheOrderPostedAcrossRuns) {
  FakeWall wall;
  EventLoop loop({ClockMode::real_time, 1.0, &wall});
  std::vector<std::string> order;
  loop.at(1.0, [&] {
    wall.t += 0.5;  // a slow callback: the loop falls behind the wall
    loop.post([&] { order.push_back("posted first"); });
  });
  loop.at(1.2, [&] { loop.stop(); });  // due before the posted callback's time (1.5)
  loop.run_until_idle();
  ASSERT_TRUE(order.empty());
  loop.post([&] { order.push_back("posted second"); });
  loop.run_until_idle();
  EXPECT_EQ(order, (std::vector<std::string>{"posted first", "posted second"}));
}

TEST(EventLoop, PostFromAnotherThreadWakesAWaitingRealTimeLoop) {
  EventLoop loop({ClockMode::real_time, 1.0, nullptr});
  bool ran = false;
  std::thread io([&] { loop.post([&] { ran = true; loop.stop(); }); });
  loop.run_until(3600.0);  // would wait an hour of wall time without the wake-up
  io.join();
  EXPECT_TRUE(ran);
  EXPECT_LT(loop.now(), 3600.0);
}

TEST(EventLoop, WallOriginFixesWhenMissionTimeZeroHappened) {
  FakeWall wall;  // now 100
  EventLoop loop({ClockMode::real_time, 2.0, &wall});
  loop.set_wall_origin(99.0);  // mission time 0 was a wall second ago: mission time is now 2
  loop.at(1.0, [] {});         // already due: no wait
  loop.at(4.0, [] {});         // wall 99 + 4 / 2 = 101
  loop.run_until_idle();
  EXPECT_EQ(wall.sleeps, (std::vector<double>{101.0}));
}

}  // namespace
}  // namespace eamos::mid
