// Missions flown in the simulator on virtual time, asserting on the trace: the first
// semantic rules of docs/language.md as executed by the DEX (semantics_test.cpp has the rest).
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "flight.h"

namespace eamos {
namespace {

/// Counts the flushes a stream asks of its buffer.
class FlushCount : public std::stringbuf {
 public:
  int flushes = 0;

 protected:
  int sync() override {
    ++flushes;
    return std::stringbuf::sync();
  }
};

// A live log flushes each line unless told it need not (a run on virtual time into a file).
TEST(LiveLog, FlushesEachLineOnlyWhenToldTo) {
  for (bool each : {true, false}) {
    FlushCount buffer;
    std::ostream out(&buffer);
    dex::LiveLog log(out);
    log.set_flush_each_line(each);
    dex::TraceEvent e;
    e.drone = "A";
    e.event = "start";
    e.text = "A.Arm()";
    for (int i = 0; i < 3; ++i) log.record(e);
    EXPECT_EQ(buffer.flushes, each ? 3 : 0);
    std::string text = buffer.str();
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 3);
  }
}

using test::Flight;
using test::example;
using test::fly;

const char* kTwo = "var A Quad\nvar B Quad\n";

TEST(Run, SequenceRunsItsStatementsOneAfterAnother) {
  Flight f = fly(std::string(kTwo) + "func INIT() { A.Arm(); A.Takeoff(5); A.Land(); A.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_LE(f.time_of("end", "A.Takeoff(5)"), f.time_of("start", "A.Land()"));
  EXPECT_LT(f.find("end", "A.Arm()"), f.find("start", "A.Takeoff(5)"));
  EXPECT_TRUE(f.result.drones[0].state.landed);
  EXPECT_FALSE(f.result.drones[0].state.armed);
}

TEST(Run, ParallelBlockStartsAllAndNextWaitsForAll) {
  Flight f = fly(std::string(kTwo) +
                 "func INIT() { PAR_up(); A.FlyByX(1) }\nfunc PAR_up() { SEQ_a(); SEQ_b() }\n"
                 "func SEQ_a() { A.Arm(); A.Takeoff(2) }\nfunc SEQ_b() { B.Arm(); B.Takeoff(8) }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_EQ(f.time_of("start", "A.Arm()"), f.time_of("start", "B.Arm()"));
  EXPECT_GE(f.time_of("start", "A.FlyByX(1)"), f.time_of("end", "B.Takeoff(8)"));
  EXPECT_LT(f.time_of("end", "A.Takeoff(2)"), f.time_of("end", "B.Takeoff(8)"));
}

TEST(Run, IfRunsOnlyTheTakenBranch) {
  Flight f = fly(std::string(kTwo) +
                 "func INIT() { A.Arm(); If(A.Battery() > 50, SEQ_t, SEQ_f); B.Arm() }\n"
                 "func SEQ_t() { A.Takeoff(3) }\nfunc SEQ_f() { A.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_GE(f.find("end", "A.Takeoff(3)", "succeeded"), 0);
  EXPECT_LT(f.find("start", "A.Disarm()"), 0);
  EXPECT_GE(f.time_of("start", "B.Arm()"), f.time_of("end", "A.Takeoff(3)"));
}

TEST(Run, WaitUntilStartsBranchWhenConditionTurnsTrue) {
  Flight f = fly(std::string(kTwo) +
                 "func INIT() { PAR_x() }\nfunc PAR_x() { SEQ_a(); WaitUntil(A.Z() >= 4, SEQ_b) }\n"
                 "func SEQ_a() { A.Arm(); A.Takeoff(8) }\nfunc SEQ_b() { B.Arm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  double go = f.time_of("start", "B.Arm()");
  EXPECT_GT(go, f.time_of("start", "A.Takeoff(8)"));
  EXPECT_LT(go, f.time_of("end", "A.Takeoff(8)"));
}

TEST(Run, RepeatForStopsAfterItsCount) {
  Flight f = fly(std::string(kTwo) +
                 "func INIT() { A.Arm(); RepeatFor(true, SEQ_r, SEQ_n, 3) }\n"
                 "func SEQ_r() { A.TakePicture() }\nfunc SEQ_n() { A.Disarm() }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_EQ(f.result.drones[0].state.pictures, 3);
  EXPECT_FALSE(f.result.drones[0].state.armed);
}

TEST(Run, DoWhileSyncCancelsDoBranchWhenConditionFlips) {
  Flight f = fly(std::string(kTwo) +
                 "func INIT() { PAR_x(); A.Land() }\n"
                 "func PAR_x() { SEQ_a(); SEQ_b() }\n"
                 "func SEQ_a() { A.Arm(); A.Takeoff(5); DoWhileSync(B.Z() < 3, SEQ_do, SEQ_done) }\n"
                 "func SEQ_b() { B.Arm(); PauseFor(10); B.Takeoff(6) }\n"
                 "func SEQ_do() { A.Orbit() }\nfunc SEQ_done() { A.Hover(1) }\n");
  ASSERT_TRUE(f.result.completed) << f.result.error;
  int cancelled = f.find("end", "A.Orbit()", "cancelled");
  EXPECT_GE(cancelled, 0);
  EXPECT_GE(f.find("end", "A.Hover(1)", "succeeded"), cancelled);
  EXPECT_LT(f.time_of("start", "A.Orbit()"), f.time_of("start", "B.Takeoff(6)"));  // B still low
  EXPECT_GE(f.time_of("start", "A.Land()"), f.time_of("end", "A.Hover(1)"));
}

TEST(Run, TakeoffWhileDisarmedFailsTheMissionNamingDroneActionAndLine) {
  // The Arm runs only above 100 % battery, never: check warns, the drone refuses at run time.
  Flight f = fly(std::string(kTwo) + "func INIT() {\n  If(A.Battery() > 100, SEQ_arm, SEQ_stay)\n  A.Takeoff(5)\n}\n"
                                     "func SEQ_arm() { A.Arm() }\nfunc SEQ_stay() { PauseFor(0) }\n");
  EXPECT_FALSE(f.result.completed);
  ASSERT_TRUE(f.result.failure.has_value());
  EXPECT_EQ(f.result.failure->drone, "A");
  EXPECT_EQ(f.result.failure->action, "Takeoff");
  EXPECT_EQ(f.result.failure->line, 5);
}

TEST(Run, SameMissionGivesByteIdenticalTrace) {
  std::string m = std::string(kTwo) +
                  "func INIT() { PAR_x() }\nfunc PAR_x() { SEQ_a(); SEQ_b() }\n"
                  "func SEQ_a() { A.Arm(); A.Takeoff(5); A.FlyTo(10, 3, 5); A.Land() }\n"
                  "func SEQ_b() { B.Arm(); B.Takeoff(3); B.Orbit(4); }\n";
  Flight one = fly(m), two = fly(m);
  EXPECT_FALSE(one.jsonl.empty());
  EXPECT_EQ(one.jsonl, two.jsonl);
}

// The examples together use all 13 control structures; each must fly to completion, with
// every drone landed and disarmed at the end.
TEST(Run, EveryExampleCompletesInTheSimulator) {
  for (const char* name : {"survey.eamos", "relay.eamos", "patrol.eamos"}) {
    Flight f = fly(example(name));
    ASSERT_TRUE(f.result.completed) << name << ": " << f.result.error;
    for (const auto& d : f.result.drones) {
      EXPECT_TRUE(d.state.landed) << name << " " << d.name;
      EXPECT_FALSE(d.state.armed) << name << " " << d.name;
    }
  }
}

// Figure 3 of the paper: Drone1 goes right (Sensor1 >= 100) or left, Drone3 waits until
// Drone1 is 5 m out, meets it there, and Drone2 orbits taking pictures until Drone3 is back
// below 3 m, when its Land preempts the Orbit; then everybody disarms.
TEST(Run, Listing2FollowsFigure3ToTheRightAndToTheLeft) {
  for (const char* side : {"right", "left"}) {
    fleet::Fleet fleet;
    Diagnostics diags;
    ASSERT_TRUE(fleet::load_fleet(std::string(EAMOS_SOURCE_DIR) + "/examples/listing2-" + side + ".yaml",
                                  fleet, diags))
        << diags.format();
    Flight f = fly(example("listing2.eamos"), fleet);
    ASSERT_TRUE(f.result.completed) << side << ": " << f.result.error;
    double x = std::string(side) == "right" ? 5.0 : -5.0;
    EXPECT_EQ(f.result.drones[0].state.x, x) << side;
    EXPECT_EQ(f.result.drones[2].state.x, x) << side;  // Drone3 flew to Drone1's x
    EXPECT_GE(f.result.drones[1].state.pictures, 1) << side;
    EXPECT_GE(f.find("end", "Drone2.Orbit()", "preempted"), 0) << side;
    std::string fly1 = std::string("Drone1.FlyByX(") + (x > 0 ? "5" : "-5") + ")";
    EXPECT_GE(f.time_of("start", "Drone3.Takeoff(3)"), f.time_of("start", fly1)) << side;
    EXPECT_GE(f.time_of("start", "Drone2.Land()"), f.time_of("end", "Drone3.FlyByX(Drone1.X())")) << side;
    for (const auto& d : f.result.drones) {
      EXPECT_TRUE(d.state.landed) << side << " " << d.name;
      EXPECT_FALSE(d.state.armed) << side << " " << d.name;
    }
  }
}

}  // namespace
}  // namespace eamos
