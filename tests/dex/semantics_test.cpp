// The execution rules of docs/language.md, one test each, on the simulator's virtual
// clock: SEQ/PAR/async, every control structure, outcomes, failures and failsafes.
#include <gtest/gtest.h>

#include <map>
#include <optional>

#include "flight.h"
#include "lang/loop_time.h"

namespace eamos {
namespace {

using test::Flight;
using test::fly;

const std::string kTwoQuads = "var A Quad\nvar B Quad\n";

TEST(Semantics, AsyncStartsBlockAndSequenceGoesOnAtOnceButMissionWaitsForIt) {
  Flight f = fly(kTwoQuads + "func INIT() { A.Arm(); async(SEQ_side); A.TakePicture() }\n"
                        "func SEQ_side() { B.Arm(); B.Takeoff(10); B.Land(); B.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_EQ(f.time_of("start", "A.TakePicture()"), f.time_of("start", "B.Arm()"));
  EXPECT_GE(f.result.duration, f.time_of("end", "B.Disarm()"));
  EXPECT_FALSE(f.result.drones[1].state.armed);
}

TEST(Semantics, PauseForHaltsTheSequenceForMissionSeconds) {
  Flight f = fly(kTwoQuads + "func INIT() { A.Arm(); PauseFor(7.5); A.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_NEAR(f.time_of("start", "A.Disarm()") - f.time_of("end", "A.Arm()"), 7.5, 1e-9);
}

TEST(Semantics, PauseUntilAndPauseWhileHaltUntilTheAwaitedState) {
  for (const char* pause : {"PauseUntil(B.Z() >= 4)", "PauseWhile(B.Z() < 4)"}) {
    Flight f = fly(kTwoQuads + "func INIT() { PAR_x() }\nfunc PAR_x() { SEQ_a(); SEQ_b() }\n"
                          "func SEQ_a() { A.Arm(); " + pause + "; A.Takeoff(2) }\n"
                          "func SEQ_b() { B.Arm(); B.Takeoff(8) }\n");
    ASSERT_TRUE(f.result.completed) << pause << ": " << f.result.error;
    double go = f.time_of("start", "A.Takeoff(2)");
    EXPECT_GT(go, f.time_of("start", "B.Takeoff(8)")) << pause;
    EXPECT_LT(go, f.time_of("end", "B.Takeoff(8)")) << pause;
  }
}

TEST(Semantics, WaitWhileRunsBranchOnceConditionTurnsFalse) {
  Flight f = fly(kTwoQuads + "func INIT() { PAR_x() }\nfunc PAR_x() { SEQ_a(); WaitWhile(A.Z() < 4, SEQ_b) }\n"
                        "func SEQ_a() { A.Arm(); A.Takeoff(8) }\nfunc SEQ_b() { B.Arm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_GT(f.time_of("start", "B.Arm()"), f.time_of("start", "A.Takeoff(8)"));
  EXPECT_LT(f.time_of("start", "B.Arm()"), f.time_of("end", "A.Takeoff(8)"));
}

TEST(Semantics, RepeatUntilRepeatsWhileFalseThenRunsAfterBranchOnce) {
  Flight f = fly(kTwoQuads + "func INIT() { A.Arm(); A.Takeoff(2); RepeatUntil(A.Z() >= 5, SEQ_up, SEQ_done) }\n"
                        "func SEQ_up() { A.FlyByZ(1) }\nfunc SEQ_done() { A.Land(); A.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  int climbs = 0;
  for (const auto& e : f.events) climbs += e.event == "end" && e.text == "A.FlyByZ(1)";
  EXPECT_EQ(climbs, 3);
  EXPECT_FALSE(f.result.drones[0].state.armed);
}

TEST(Semantics, RepeatWhileAndRepeatForRunNoIterationWhenConditionFailsFirst) {
  for (const char* repeat : {"RepeatWhile(A.Z() > 100, SEQ_r, SEQ_n)", "RepeatFor(false, SEQ_r, SEQ_n, 5)"}) {
    Flight f = fly(kTwoQuads + "func INIT() { A.Arm(); " + repeat + " }\n"
                          "func SEQ_r() { A.TakePicture() }\nfunc SEQ_n() { A.Disarm() }\n");
    ASSERT_TRUE(f.result.completed) << repeat << ": " << f.result.error;
    EXPECT_EQ(f.result.drones[0].state.pictures, 0) << repeat;
    EXPECT_GE(f.find("end", "A.Disarm()", "succeeded"), 0) << repeat;
  }
}

TEST(Semantics, DoSyncThatSaysDontContinuesAtOnceWithoutDoneBranch) {
  Flight f = fly(kTwoQuads + "func INIT() { A.Arm(); DoUntilSync(A.Armed(), SEQ_do, SEQ_done); A.Disarm() }\n"
                        "func SEQ_do() { A.Takeoff(3) }\nfunc SEQ_done() { A.TakePicture() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_LT(f.find("start", "A.Takeoff(3)"), 0);
  EXPECT_LT(f.find("start", "A.TakePicture()"), 0);
  EXPECT_EQ(f.time_of("start", "A.Disarm()"), f.time_of("end", "A.Arm()"));
}

TEST(Semantics, DoSyncWhoseDoBranchEndsByItselfSkipsTheDoneBranch) {
  Flight f = fly(kTwoQuads + "func INIT() { A.Arm(); DoWhileSync(A.Battery() > 10, SEQ_do, SEQ_done); A.Disarm() }\n"
                        "func SEQ_do() { A.Takeoff(3); A.Land() }\nfunc SEQ_done() { A.TakePicture() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_LT(f.find("start", "A.TakePicture()"), 0);
  EXPECT_GE(f.time_of("start", "A.Disarm()"), f.time_of("end", "A.Land()"));
}

TEST(Semantics, DoAsyncDetachesDoBranchAndFlipCancelsItOnEveryDrone) {
  Flight f = fly(kTwoQuads +
                 "func INIT() { PAR_up(); DoWhileAsync(A.Z() < 6, PAR_circle, SEQ_home); A.FlyByZ(5) }\n"
                 "func PAR_up() { SEQ_a(); SEQ_b() }\n"
                 "func SEQ_a() { A.Arm(); A.Takeoff(3) }\nfunc SEQ_b() { B.Arm(); B.Takeoff(3) }\n"
                 "func PAR_circle() { B.Orbit(); B.TakePicture() }\n"
                 "func SEQ_home() { B.ReturnHome(); B.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_EQ(f.time_of("start", "A.FlyByZ(5)"), f.time_of("start", "B.Orbit()"));  // detached
  // The flip cancels the orbit before the done-branch starts; the cancelled action's end
  // is reported by the drone a moment later (same mission time).
  int cancelled = f.find("end", "B.Orbit()", "cancelled");
  ASSERT_GE(cancelled, 0);
  EXPECT_EQ(f.time_of("start", "B.ReturnHome()"), f.events[cancelled].t);
  EXPECT_GE(f.result.duration, f.time_of("end", "B.Disarm()"));
  EXPECT_TRUE(f.result.drones[1].state.landed);
}

TEST(Semantics, DoUntilAsyncRunsDoBranchUntilConditionTurnsTrueThenDoneBranch) {
  Flight f = fly(kTwoQuads + "func INIT() { PAR_up(); PAR_main() }\n"
                        "func PAR_up() { SEQ_a(); B.Arm() }\nfunc SEQ_a() { A.Arm(); A.Takeoff(3) }\n"
                        "func PAR_main() { SEQ_watch(); SEQ_b() }\n"
                        "func SEQ_watch() { DoUntilAsync(B.Z() > 4, SEQ_do, SEQ_done); A.TakePicture() }\n"
                        "func SEQ_do() { A.Orbit(3) }\nfunc SEQ_done() { A.Land(); A.Disarm() }\n"
                        "func SEQ_b() { PauseFor(5); B.Takeoff(8); B.Land(); B.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_EQ(f.time_of("start", "A.TakePicture()"), f.time_of("start", "A.Orbit(3)"));  // detached
  int cancelled = f.find("end", "A.Orbit(3)", "cancelled");
  ASSERT_GE(cancelled, 0);
  EXPECT_GT(f.events[cancelled].t, f.time_of("start", "B.Takeoff(8)"));
  EXPECT_LT(f.events[cancelled].t, f.time_of("end", "B.Takeoff(8)"));
  EXPECT_EQ(f.time_of("start", "A.Land()"), f.events[cancelled].t);
  EXPECT_FALSE(f.result.drones[0].state.armed);
}

// A do-branch spanning two drones, cancelled in every iteration of a loop: each run starts
// afresh on both drones (epochs), nothing of a cancelled run leaks into the next.
TEST(Semantics, DoInsideRepeatIsCancelledAndRestartedOnEveryDroneEachIteration) {
  Flight f = fly(kTwoQuads + "func INIT() { PAR_up(); RepeatFor(true, SEQ_iter, SEQ_end, 3) }\n"
                        "func PAR_up() { SEQ_a(); SEQ_b() }\n"
                        "func SEQ_a() { A.Arm(); A.Takeoff(3) }\nfunc SEQ_b() { B.Arm(); B.Takeoff(3) }\n"
                        "func SEQ_iter() { DoWhileSync(A.Z() < 6, PAR_work, SEQ_reset); PauseFor(0.5) }\n"
                        "func PAR_work() { A.FlyByZ(5); SEQ_bw() }\n"
                        "func SEQ_bw() { B.TakePicture(); B.Hover(30) }\n"
                        "func SEQ_reset() { A.FlyTo(0, 0, 3) }\n"
                        "func SEQ_end() { PAR_land() }\nfunc PAR_land() { SEQ_la(); SEQ_lb() }\n"
                        "func SEQ_la() { A.Land(); A.Disarm() }\nfunc SEQ_lb() { B.Land(); B.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  int climbs_cancelled = 0, hovers_cancelled = 0, hovers_done = 0;
  for (const auto& e : f.events) {
    climbs_cancelled += e.event == "end" && e.text == "A.FlyByZ(5)" && e.outcome == "cancelled";
    hovers_cancelled += e.event == "end" && e.text == "B.Hover(30)" && e.outcome == "cancelled";
    hovers_done += e.event == "end" && e.text == "B.Hover(30)" && e.outcome == "succeeded";
  }
  EXPECT_EQ(climbs_cancelled, 3);
  EXPECT_EQ(hovers_cancelled, 3);
  EXPECT_EQ(hovers_done, 0);
  EXPECT_EQ(f.result.drones[1].state.pictures, 3);
  EXPECT_FALSE(f.result.drones[0].state.armed);
  EXPECT_FALSE(f.result.drones[1].state.armed);
}

TEST(Semantics, ConditionReadsOtherDronesTelemetryFromTheFirstInstant) {
  // B evaluates (it is read twice); A's position comes from A's telemetry, known at t = 0.
  Flight f = fly(kTwoQuads + "func INIT() { If(A.Y() == 0 && B.Y() == 5 && B.X() == 0, SEQ_t, SEQ_f) }\n"
                        "func SEQ_t() { A.Arm() }\nfunc SEQ_f() { A.TakePicture() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_GE(f.find("end", "A.Arm()", "succeeded"), 0);
}

TEST(Semantics, ConditionEvaluatedByOneDroneDecidesForTheOthers) {
  Flight f = fly(kTwoQuads + "func INIT() { A.Arm(); B.Arm(); If(A.Armed(), PAR_yes, PAR_no) }\n"
                        "func PAR_yes() { B.TakePicture() }\nfunc PAR_no() { B.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  int evaluations = 0;
  for (const auto& e : f.events) evaluations += e.event == "condition";
  EXPECT_EQ(evaluations, 1);
  EXPECT_EQ(f.events[f.find("start", "B.TakePicture()")].drone, "B");
  EXPECT_LT(f.find("start", "B.Disarm()"), 0);
}

TEST(Semantics, NewMotionPreemptsTheRunningOneWhichEndsPreempted) {
  Flight f = fly(kTwoQuads + "func INIT() { A.Arm(); A.Takeoff(3); PAR_x() }\n"
                        "func PAR_x() { A.Orbit(); SEQ_later() }\nfunc SEQ_later() { PauseFor(4); A.Land() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_GE(f.find("end", "A.Orbit()", "preempted"), 0);
  EXPECT_EQ(f.events[f.find("end", "A.Orbit()")].reason, "preempted by Land");
}

TEST(Semantics, PayloadActionRunsBesideMotion) {
  Flight f = fly(kTwoQuads + "func INIT() { A.Arm(); A.Takeoff(3); PAR_x() }\n"
                        "func PAR_x() { A.FlyTo(30, 0, 3); A.TakePicture() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_GE(f.find("end", "A.FlyTo(30, 0, 3)", "succeeded"), 0);
  EXPECT_LT(f.time_of("end", "A.TakePicture()"), f.time_of("end", "A.FlyTo(30, 0, 3)"));
}

TEST(Semantics, EveryStartedActionEndsExactlyOnce) {
  Flight f = fly(test::example("listing2.eamos"));
  std::map<std::string, int> open;
  for (const auto& e : f.events) {
    if (e.event == "start") ++open[e.drone + e.text];
    if (e.event == "end") --open[e.drone + e.text];
  }
  for (const auto& [action, n] : open) EXPECT_EQ(n, 0) << action;
}

TEST(Semantics, DisarmInTheAirFailsTheMissionAndAirborneDronesRunTheirFailsafe) {
  Flight f = fly(kTwoQuads + "func INIT() { PAR_up() }\n"
                        "func PAR_up() { SEQ_a(); SEQ_b() }\n"
                        "func SEQ_a() { A.Arm(); A.Takeoff(3); A.Disarm() }\n"
                        "func SEQ_b() { B.Arm(); B.Takeoff(5); B.Orbit() }\n");
  EXPECT_FALSE(f.result.completed);
  ASSERT_TRUE(f.result.failure.has_value());
  EXPECT_EQ(f.result.failure->drone, "A");
  EXPECT_EQ(f.result.failure->action, "Disarm");
  EXPECT_EQ(f.result.failure->line, 5);
  for (const auto& d : f.result.drones) EXPECT_TRUE(d.state.landed) << d.name;  // failsafe: land
  EXPECT_GE(f.find("end", "B.Takeoff(5)", "cancelled"), 0);  // B was still climbing
  EXPECT_LT(f.find("start", "B.Orbit()"), 0);                // nothing new starts
}

TEST(Semantics, AbandonedMissionTracesAFailsafeForEveryDroneNotYetSafe) {
  // A fails on the ground while B is in the air and C is armed on the ground: B lands, C is
  // disarmed, A (landed, never armed) is already safe. Each failsafe is a trace event.
  Flight f = fly("package p\nvar A Quad\nvar B Quad\nvar C Quad\n"
                 "func INIT() { PAR_all() }\n"
                 "func PAR_all() { SEQ_a(); SEQ_b(); C.Arm() }\n"
                 "func SEQ_a() { PauseFor(3); If(A.Battery() > 100, SEQ_arm, SEQ_stay); A.Takeoff(3) }\n"
                 "func SEQ_arm() { A.Arm() }\nfunc SEQ_stay() { PauseFor(0) }\n"
                 "func SEQ_b() { B.Arm(); B.Takeoff(5); B.Orbit() }\n");
  ASSERT_TRUE(f.result.failure.has_value());
  EXPECT_EQ(f.result.failure->drone, "A");
  std::map<std::string, const dex::TraceEvent*> failsafe;
  for (const auto& e : f.events)
    if (e.event == "failsafe") failsafe[e.drone] = &e;
  EXPECT_EQ(failsafe.count("A"), 0u);
  ASSERT_EQ(failsafe.count("B"), 1u);
  ASSERT_EQ(failsafe.count("C"), 1u);
  EXPECT_EQ(failsafe["B"]->name, "land");
  EXPECT_EQ(failsafe["B"]->reason, f.result.error);
  EXPECT_DOUBLE_EQ(failsafe["B"]->t, f.time_of("end", "A.Takeoff(3)"));
  for (const auto& d : f.result.drones) {
    EXPECT_TRUE(d.state.landed) << d.name;
    EXPECT_FALSE(d.state.armed) << d.name;
  }
}

TEST(Semantics, ActionExceedingItsFleetTimeoutFails) {
  fleet::Fleet fleet;
  Diagnostics diags;
  ASSERT_TRUE(fleet::parse_fleet(std::make_shared<SourceFile>("f.yaml", "drones:\n  A:\n    timeouts: {FlyTo: 2}\n"),
                                 fleet, diags))
      << diags.format();
  Flight f = fly(kTwoQuads + "func INIT() { A.Arm(); A.Takeoff(3); A.FlyTo(100, 0, 3) }\n", fleet);
  EXPECT_FALSE(f.result.completed);
  ASSERT_TRUE(f.result.failure.has_value());
  EXPECT_EQ(f.result.failure->action, "FlyTo");
  EXPECT_NE(f.result.failure->reason.find("timed out"), std::string::npos) << f.result.failure->reason;
}

// --- Loops that take no time. `eamos check` refuses such loops; the DEX must
// still never hang on one, since a mission file is input like any other. The missions are
// compiled with a picture in the loop, which the test then turns into a fork (no time).

const std::string kOne = "var A Quad\n";

int count_of(const Flight& f, const std::string& event, const std::string& text, const std::string& outcome = "") {
  int n = 0;
  for (const auto& e : f.events)
    n += e.event == event && e.text == text && (outcome.empty() || e.outcome == outcome);
  return n;
}

// The checker warns instead of refusing a RepeatFor below the DEX's guard: the two numbers
// must be one.
TEST(Semantics, TheCheckersBoundedLoopCountIsTheDexsGuard) {
  EXPECT_EQ(lang::kMaxInstantIterations, dex::kMaxInstantIterations);
}

// A RepeatFor of 3 whose body may take no time is a warning, and flies to its end.
TEST(Semantics, BoundedLoopWhoseBodyMayTakeNoTimeRunsItsCountAndGoesOn) {
  test::Flight f = test::fly(
      "var A Quad\nfunc INIT() { A.Arm(); A.Takeoff(5); RepeatFor(true, SEQ_w, SEQ_after, 3) }\n"
      "func SEQ_w() { DoWhileSync(A.Battery() < 5, SEQ_h, SEQ_d) }\nfunc SEQ_h() { A.Hover(1) }\n"
      "func SEQ_d() { A.TakePicture() }\nfunc SEQ_after() { A.Land() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_GE(f.find("end", "A.Land()", "succeeded"), 0);
}

TEST(Semantics, LoopThatTakesNoTimeFailsTheMissionAndRunsTheFailsafeInsteadOfSpinning) {
  Flight f = test::fly_missions(test::missions_of(
      kOne + "func INIT() { A.Arm(); A.Takeoff(3); RepeatWhile(A.Battery() > 1, SEQ_r, SEQ_n) }\n"
             "func SEQ_r() { A.TakePicture() }\nfunc SEQ_n() { A.Land() }\n",
      {}, test::without_action("A.TakePicture()")));
  EXPECT_FALSE(f.result.completed);
  ASSERT_TRUE(f.result.failure.has_value()) << f.result.error;
  EXPECT_EQ(f.result.failure->action, "RepeatWhile");
  EXPECT_EQ(f.result.failure->line, 2);
  EXPECT_NE(f.result.error.find("took no mission time"), std::string::npos) << f.result.error;
  EXPECT_DOUBLE_EQ(f.result.duration, f.time_of("end", "A.Takeoff(3)"));
  int failsafe = -1;
  for (std::size_t i = 0; i < f.events.size(); ++i)
    if (f.events[i].event == "failsafe") failsafe = static_cast<int>(i);
  ASSERT_GE(failsafe, 0);
  EXPECT_EQ(f.events[failsafe].drone, "A");
  EXPECT_TRUE(f.result.drones[0].state.landed);
  EXPECT_FALSE(f.result.drones[0].state.armed);
}

// Each iteration is one event of the loop: work of other drones at the same instant (here
// B's Arm, a trigger through the transport) gets its turn while the loop spins.
TEST(Semantics, LoopThatTakesNoTimeYieldsToTheEventLoopAtEveryIteration) {
  Flight f = test::fly_missions(test::missions_of(
      kTwoQuads + "func INIT() { PAR_x() }\nfunc PAR_x() { SEQ_loop(); SEQ_b() }\n"
             "func SEQ_loop() { RepeatFor(A.Battery() > 0, SEQ_r, SEQ_n, 1000000000) }\n"
             "func SEQ_r() { A.TakePicture() }\nfunc SEQ_n() { A.Disarm() }\n"
             "func SEQ_b() { B.Arm(); B.TakePicture() }\n",
      {}, test::without_action("A.TakePicture()")));
  ASSERT_TRUE(f.result.failure.has_value());
  EXPECT_EQ(f.result.failure->action, "RepeatFor");
  EXPECT_GE(f.find("end", "B.Arm()", "succeeded"), 0);
  EXPECT_GE(f.find("start", "B.TakePicture()"), 0);
  EXPECT_EQ(count_of(f, "condition", "A.Battery() > 0"), dex::kMaxInstantIterations);
  EXPECT_FALSE(f.result.drones[1].state.armed);  // B's failsafe disarmed it on the ground
}

// A RepeatFor of 10^9 instant iterations, driven one loop event at a time: starting the
// engine returns at once, and every event runs exactly one iteration (no call stack, no
// inner loop that holds the thread).
TEST(Semantics, LoopThatTakesNoTimeRunsOneIterationPerEventLoopCallback) {
  std::vector<dex::Mission> missions = test::missions_of(
      kOne + "func INIT() { RepeatFor(true, SEQ_r, SEQ_n, 1000000000) }\n"
             "func SEQ_r() { A.TakePicture() }\nfunc SEQ_n() { A.Arm() }\n",
      {}, test::without_action("A.TakePicture()"));
  ASSERT_EQ(missions.size(), 1u);
  mid::AdapterRegistry adapters;
  sim::register_adapter(adapters);
  mid::EventLoop loop;
  mid::CreateResult made = adapters.create(missions[0].settings.adapter, missions[0].settings, missions[0].type, loop);
  ASSERT_EQ(made.status, mid::CreateStatus::success) << made.message;
  // Each evaluation of the condition stops the loop after the callback it happened in.
  struct StopAtEachEvaluation : dex::TraceSink {
    mid::EventLoop& loop;
    std::size_t evaluations = 0;
    explicit StopAtEachEvaluation(mid::EventLoop& l) : loop(l) {}
    void record(const dex::TraceEvent& e) override {
      evaluations += e.event == "condition";
      loop.stop();
    }
  } trace(loop);
  std::optional<dex::Failure> failure;
  dex::EngineHooks hooks;
  hooks.trace = &trace;
  hooks.on_failure = [&](const dex::Failure& f) { failure = f; };
  dex::Engine engine(missions[0], *made.drone, loop, hooks);
  engine.start();
  EXPECT_EQ(trace.evaluations, 1u);  // the first iteration, then back to the caller
  EXPECT_TRUE(engine.busy());        // the next one waits for its turn
  for (std::size_t i = 2; i <= 100; ++i) {
    ASSERT_EQ(loop.run_until(0.0), 1u);  // one callback ...
    ASSERT_EQ(trace.evaluations, i);     // ... one iteration
  }
  while (!failure && loop.size() > 0) loop.run_until(0.0);  // it fails; it does not run for ever
  ASSERT_TRUE(failure.has_value());
  EXPECT_EQ(failure->action, "RepeatFor");
  EXPECT_EQ(trace.evaluations, static_cast<std::size_t>(dex::kMaxInstantIterations));
}

// --- async work started again by a loop while it still runs: each start is an
// instance of its own that ends, and is traced, exactly once.

TEST(Semantics, AsyncWorkStartedAgainByALoopBeforeItEndedEndsOnceForEveryStart) {
  // Iterations take 0.2 s, a picture 0.5 s: three pictures overlap.
  Flight f = fly(kOne + "func INIT() { A.Arm(); A.Takeoff(3); RepeatFor(true, SEQ_r, SEQ_n, 3) }\n"
                        "func SEQ_r() { async(SEQ_pic); PauseFor(0.2) }\nfunc SEQ_pic() { A.TakePicture() }\n"
                        "func SEQ_n() { A.Land(); A.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_EQ(count_of(f, "start", "A.TakePicture()"), 3);
  EXPECT_EQ(count_of(f, "end", "A.TakePicture()", "succeeded"), 3);
  EXPECT_EQ(f.result.drones[0].state.pictures, 3);
  EXPECT_LT(f.result.duration, 60.0);  // not the time limit
}

TEST(Semantics, AsyncMotionStartedAgainByALoopPreemptsTheRunningOneWhichEndsPreempted) {
  Flight f = fly(kOne + "func INIT() { A.Arm(); A.Takeoff(3); RepeatFor(true, SEQ_r, SEQ_n, 2) }\n"
                        "func SEQ_r() { async(SEQ_up); PauseFor(0.2) }\nfunc SEQ_up() { A.FlyByZ(2) }\n"
                        "func SEQ_n() { PauseFor(20); A.Land(); A.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_EQ(count_of(f, "start", "A.FlyByZ(2)"), 2);
  EXPECT_EQ(count_of(f, "end", "A.FlyByZ(2)"), 2);
  int first = f.find("end", "A.FlyByZ(2)");
  EXPECT_EQ(f.events[first].outcome, "preempted");
  EXPECT_EQ(f.events[first].reason, "preempted by FlyByZ");
  EXPECT_EQ(count_of(f, "end", "A.FlyByZ(2)", "succeeded"), 1);
  EXPECT_LT(f.result.duration, 60.0);
}

// Async work spanning drones goes on while the next iteration runs: C's second picture of
// iteration 1 follows B's picture, which ends (at 1.0 s) after C has heard of iteration 2
// (at 0.75 s) and B has not. Its trigger belongs to iteration 1 and is not stale.
TEST(Semantics, AsyncWorkAcrossDronesKeepsItsTriggersWhileTheNextIterationRuns) {
  Flight f = fly("var A Quad\nvar B Quad\nvar C Quad\n"
                 "func INIT() { RepeatFor(A.Battery() > 0, SEQ_r, SEQ_n, 2) }\n"
                 "func SEQ_r() { async(SEQ_w); PauseFor(0.75) }\n"
                 "func SEQ_w() { C.TakePicture(); B.TakePicture(); C.TakePicture() }\n"
                 "func SEQ_n() { A.Arm(); A.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_EQ(f.result.drones[1].state.pictures, 2);
  EXPECT_EQ(f.result.drones[2].state.pictures, 4);
  EXPECT_DOUBLE_EQ(f.result.duration, 2.25);  // iteration 2's last picture: 0.75 + 3 × 0.5
}

TEST(Semantics, DoAsyncStartedAgainWhileItsDoBranchRunsCancelsThatRunFirst) {
  Flight f = fly(kTwoQuads + "func INIT() { PAR_up(); RepeatFor(true, SEQ_r, SEQ_n, 2) }\n"
                        "func PAR_up() { SEQ_a(); SEQ_b() }\n"
                        "func SEQ_a() { A.Arm(); A.Takeoff(3) }\nfunc SEQ_b() { B.Arm(); B.Takeoff(3) }\n"
                        "func SEQ_r() { DoWhileAsync(A.Z() < 100, SEQ_do, SEQ_done); PauseFor(1) }\n"
                        "func SEQ_do() { B.Orbit() }\nfunc SEQ_done() { B.TakePicture() }\n"
                        "func SEQ_n() { PAR_land() }\nfunc PAR_land() { SEQ_la(); SEQ_lb() }\n"
                        "func SEQ_la() { A.Land(); A.Disarm() }\nfunc SEQ_lb() { B.Land(); B.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_EQ(count_of(f, "start", "B.Orbit()"), 2);
  EXPECT_EQ(count_of(f, "end", "B.Orbit()", "cancelled"), 1);  // the first run, by the second
  EXPECT_EQ(count_of(f, "end", "B.Orbit()", "preempted"), 1);  // the second, by B.Land()
  EXPECT_EQ(count_of(f, "start", "B.TakePicture()"), 0);       // a superseded run has no done-branch
  EXPECT_FALSE(f.result.drones[1].state.armed);
}

// --- Completion: the mission completes at the instant its last work ends, and
// the trace says so last.

TEST(Semantics, MissionWhoseLastWorkIsAsyncCompletesWhenThatWorkEnds) {
  // A sensor read changes no published state: nothing but the engine going idle says it ended.
  Flight f = fly(kOne + "func INIT() { A.Arm(); async(SEQ_read) }\nfunc SEQ_read() { PauseFor(2); A.Sensor1() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_DOUBLE_EQ(f.result.duration, f.time_of("end", "A.Sensor1()"));
  EXPECT_DOUBLE_EQ(f.result.duration, 2.1);
}

TEST(Semantics, DoAsyncDoneBranchThatEndsLastCompletesTheMissionWhenItEnds) {
  Flight f = fly(kOne + "func INIT() { A.Arm(); A.Takeoff(3); DoWhileAsync(A.Z() < 5, SEQ_do, SEQ_done); A.FlyByZ(4) }\n"
                        "func SEQ_do() { PauseFor(100) }\nfunc SEQ_done() { PauseFor(3); A.Sensor1() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  double last_end = 0;
  for (const auto& e : f.events)
    if (e.event == "end") last_end = e.t;
  EXPECT_DOUBLE_EQ(f.result.duration, last_end);
  // The last action's events (the nodes after it, terminals and the end node, have "node" events).
  std::vector<dex::TraceEvent> actions;
  for (const auto& e : f.events)
    if (e.event == "start" || e.event == "end" || e.event == "sensor" || e.event == "mission") actions.push_back(e);
  ASSERT_GE(actions.size(), 2u);
  EXPECT_EQ(actions[actions.size() - 2].text, "A.Sensor1()");
}

// A still, armed drone publishes its state once a second (the simulator's idle telemetry):
// B at 1 and 2 s. The If is A's and reads B, so B's samples go to A. A's pause ends at 2 s,
// but was scheduled (at 1.5 s) after B's timer for 2 s (at 1 s): B's sample of 2 s is still
// on its way to A when A reaches the end node.
// Telemetry cannot start anything in a fleet whose engines are all idle: counted as a message
// in flight, it would keep the run waiting for the time limit although every drone had
// reached the end.
TEST(Semantics, MissionCompletesWhenItsLastWorkEndsWithTelemetryStillOnItsWay) {
  Flight f = fly(kTwoQuads + "func INIT() { PAR_x() }\nfunc PAR_x() { A.Arm(); SEQ_b() }\n"
                        "func SEQ_b() { B.Arm(); PauseFor(1.5); If(A.Armed() && B.Armed(), SEQ_p, SEQ_p) }\n"
                        "func SEQ_p() { PauseFor(0.5) }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_DOUBLE_EQ(f.result.duration, 2.0);
}

TEST(Semantics, TraceEndsWithTheMissionEventAtTheInstantTheMissionEnded) {
  Flight done = fly(kOne + "func INIT() { A.Arm(); A.Disarm() }\n");
  ASSERT_TRUE(done.result.completed) << done.result.error;
  ASSERT_FALSE(done.events.empty());
  const dex::TraceEvent& last = done.events.back();
  EXPECT_EQ(last.event, "mission");
  EXPECT_EQ(last.outcome, "completed");
  EXPECT_EQ(last.t, done.result.duration);
  EXPECT_EQ(last.reason, "");
  EXPECT_NE(done.jsonl.find("{\"t\":0.0,\"drone\":\"\",\"event\":\"mission\",\"name\":\"\",\"line\":0,"
                            "\"outcome\":\"completed\"}\n"),
            std::string::npos)
      << done.jsonl;

  Flight failed = fly(kOne + "func INIT() { A.Arm(); A.Takeoff(3); A.Disarm() }\n");
  ASSERT_FALSE(failed.result.completed);
  const dex::TraceEvent& end = failed.events.back();
  EXPECT_EQ(end.event, "mission");
  EXPECT_EQ(end.outcome, "failed");
  EXPECT_EQ(end.reason, failed.result.error);
  EXPECT_EQ(end.t, failed.time_of("end", "A.Disarm()"));
}

}  // namespace
}  // namespace eamos
