// The execution rules of docs/language.md, one test each, on the simulator's virtual
// clock: SEQ/PAR/async, every control structure, outcomes, failures and failsafes.
#include <gtest/gtest.h>

#include <map>

#include "flight.h"

namespace eamos {
namespace {

using test::Flight;
using test::fly;

const std::string kTwo = "var A Quad\nvar B Quad\n";

TEST(Semantics, AsyncStartsBlockAndSequenceGoesOnAtOnceButMissionWaitsForIt) {
  Flight f = fly(kTwo + "func INIT() { A.Arm(); async(SEQ_side); A.TakePicture() }\n"
                        "func SEQ_side() { B.Arm(); B.Takeoff(10); B.Land(); B.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_EQ(f.time_of("start", "A.TakePicture()"), f.time_of("start", "B.Arm()"));
  EXPECT_GE(f.result.duration, f.time_of("end", "B.Disarm()"));
  EXPECT_FALSE(f.result.drones[1].state.armed);
}

TEST(Semantics, PauseForHaltsTheSequenceForMissionSeconds) {
  Flight f = fly(kTwo + "func INIT() { A.Arm(); PauseFor(7.5); A.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_NEAR(f.time_of("start", "A.Disarm()") - f.time_of("end", "A.Arm()"), 7.5, 1e-9);
}

TEST(Semantics, PauseUntilAndPauseWhileHaltUntilTheAwaitedState) {
  for (const char* pause : {"PauseUntil(B.Z() >= 4)", "PauseWhile(B.Z() < 4)"}) {
    Flight f = fly(kTwo + "func INIT() { PAR_x() }\nfunc PAR_x() { SEQ_a(); SEQ_b() }\n"
                          "func SEQ_a() { A.Arm(); " + pause + "; A.Takeoff(2) }\n"
                          "func SEQ_b() { B.Arm(); B.Takeoff(8) }\n");
    ASSERT_TRUE(f.result.completed) << pause << ": " << f.result.error;
    double go = f.time_of("start", "A.Takeoff(2)");
    EXPECT_GT(go, f.time_of("start", "B.Takeoff(8)")) << pause;
    EXPECT_LT(go, f.time_of("end", "B.Takeoff(8)")) << pause;
  }
}

TEST(Semantics, WaitWhileRunsBranchOnceConditionTurnsFalse) {
  Flight f = fly(kTwo + "func INIT() { PAR_x() }\nfunc PAR_x() { SEQ_a(); WaitWhile(A.Z() < 4, SEQ_b) }\n"
                        "func SEQ_a() { A.Arm(); A.Takeoff(8) }\nfunc SEQ_b() { B.Arm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_GT(f.time_of("start", "B.Arm()"), f.time_of("start", "A.Takeoff(8)"));
  EXPECT_LT(f.time_of("start", "B.Arm()"), f.time_of("end", "A.Takeoff(8)"));
}

TEST(Semantics, RepeatUntilRepeatsWhileFalseThenRunsAfterBranchOnce) {
  Flight f = fly(kTwo + "func INIT() { A.Arm(); A.Takeoff(2); RepeatUntil(A.Z() >= 5, SEQ_up, SEQ_done) }\n"
                        "func SEQ_up() { A.FlyByZ(1) }\nfunc SEQ_done() { A.Land(); A.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  int climbs = 0;
  for (const auto& e : f.events) climbs += e.event == "end" && e.text == "A.FlyByZ(1)";
  EXPECT_EQ(climbs, 3);
  EXPECT_FALSE(f.result.drones[0].state.armed);
}

TEST(Semantics, RepeatWhileAndRepeatForRunNoIterationWhenConditionFailsFirst) {
  for (const char* repeat : {"RepeatWhile(A.Z() > 100, SEQ_r, SEQ_n)", "RepeatFor(false, SEQ_r, SEQ_n, 5)"}) {
    Flight f = fly(kTwo + "func INIT() { A.Arm(); " + repeat + " }\n"
                          "func SEQ_r() { A.TakePicture() }\nfunc SEQ_n() { A.Disarm() }\n");
    ASSERT_TRUE(f.result.completed) << repeat << ": " << f.result.error;
    EXPECT_EQ(f.result.drones[0].state.pictures, 0) << repeat;
    EXPECT_GE(f.find("end", "A.Disarm()", "succeeded"), 0) << repeat;
  }
}

TEST(Semantics, DoSyncThatSaysDontContinuesAtOnceWithoutDoneBranch) {
  Flight f = fly(kTwo + "func INIT() { A.Arm(); DoUntilSync(A.Armed(), SEQ_do, SEQ_done); A.Disarm() }\n"
                        "func SEQ_do() { A.Takeoff(3) }\nfunc SEQ_done() { A.TakePicture() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_LT(f.find("start", "A.Takeoff(3)"), 0);
  EXPECT_LT(f.find("start", "A.TakePicture()"), 0);
  EXPECT_EQ(f.time_of("start", "A.Disarm()"), f.time_of("end", "A.Arm()"));
}

TEST(Semantics, DoSyncWhoseDoBranchEndsByItselfSkipsTheDoneBranch) {
  Flight f = fly(kTwo + "func INIT() { A.Arm(); DoWhileSync(A.Battery() > 10, SEQ_do, SEQ_done); A.Disarm() }\n"
                        "func SEQ_do() { A.Takeoff(3); A.Land() }\nfunc SEQ_done() { A.TakePicture() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_LT(f.find("start", "A.TakePicture()"), 0);
  EXPECT_GE(f.time_of("start", "A.Disarm()"), f.time_of("end", "A.Land()"));
}

TEST(Semantics, DoAsyncDetachesDoBranchAndFlipCancelsItOnEveryDrone) {
  Flight f = fly(kTwo +
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
  Flight f = fly(kTwo + "func INIT() { PAR_up(); PAR_main() }\n"
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
  Flight f = fly(kTwo + "func INIT() { PAR_up(); RepeatFor(true, SEQ_iter, SEQ_end, 3) }\n"
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
  Flight f = fly(kTwo + "func INIT() { If(A.Y() == 0 && B.Y() == 5 && B.X() == 0, SEQ_t, SEQ_f) }\n"
                        "func SEQ_t() { A.Arm() }\nfunc SEQ_f() { A.TakePicture() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_GE(f.find("end", "A.Arm()", "succeeded"), 0);
}

TEST(Semantics, ConditionEvaluatedByOneDroneDecidesForTheOthers) {
  Flight f = fly(kTwo + "func INIT() { A.Arm(); B.Arm(); If(A.Armed(), PAR_yes, PAR_no) }\n"
                        "func PAR_yes() { B.TakePicture() }\nfunc PAR_no() { B.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  int evaluations = 0;
  for (const auto& e : f.events) evaluations += e.event == "condition";
  EXPECT_EQ(evaluations, 1);
  EXPECT_EQ(f.events[f.find("start", "B.TakePicture()")].drone, "B");
  EXPECT_LT(f.find("start", "B.Disarm()"), 0);
}

TEST(Semantics, NewMotionPreemptsTheRunningOneWhichEndsPreempted) {
  Flight f = fly(kTwo + "func INIT() { A.Arm(); A.Takeoff(3); PAR_x() }\n"
                        "func PAR_x() { A.Orbit(); SEQ_later() }\nfunc SEQ_later() { PauseFor(4); A.Land() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_GE(f.find("end", "A.Orbit()", "preempted"), 0);
  EXPECT_EQ(f.events[f.find("end", "A.Orbit()")].reason, "preempted by Land");
}

TEST(Semantics, PayloadActionRunsBesideMotion) {
  Flight f = fly(kTwo + "func INIT() { A.Arm(); A.Takeoff(3); PAR_x() }\n"
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
  Flight f = fly(kTwo + "func INIT() { PAR_up() }\n"
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
                 "func SEQ_a() { PauseFor(3); A.Takeoff(3) }\n"
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
  Flight f = fly(kTwo + "func INIT() { A.Arm(); A.Takeoff(3); A.FlyTo(100, 0, 3) }\n", fleet);
  EXPECT_FALSE(f.result.completed);
  ASSERT_TRUE(f.result.failure.has_value());
  EXPECT_EQ(f.result.failure->action, "FlyTo");
  EXPECT_NE(f.result.failure->reason.find("timed out"), std::string::npos) << f.result.failure->reason;
}

}  // namespace
}  // namespace eamos
