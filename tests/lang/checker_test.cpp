// Whole-file behaviour of the checker: every error in one run, robustness against hostile
// input, Listing 2 as the paper printed it. Single rules live in diagnostics/ files.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "graph/pipeline.h"
#include "lang/altitude.h"
#include "lang/arming.h"

namespace eamos {
namespace {

struct Result {
  bool ok;
  std::string text;
  std::size_t errors;
  std::size_t warnings;
};

Result check(const std::string& text) {
  graph::Compilation c;
  Diagnostics d;
  d.max_errors = 0;
  bool ok = graph::compile(std::make_shared<SourceFile>("m.eamos", text), fleet::Fleet{}, d, c);
  return {ok, d.format(), d.error_count(), d.warning_count()};
}

std::string read_file(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The orbit preemption is deliberate and the only warning: the example compares positions
// with the goal tolerance, never exactly (a real estimate is never exactly 0), so it means
// the same on a real vehicle as in the simulator.
TEST(Checker, Listing2CompilesWithOnlyTheOrbitPreemptionWarning) {
  Result r = check(read_file(std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos"));
  EXPECT_TRUE(r.ok) << r.text;
  EXPECT_EQ(r.warnings, 1u) << r.text;
  EXPECT_EQ(r.text.find("compares a measured value exactly"), std::string::npos) << r.text;
  EXPECT_NE(r.text.find("'Drone2' may run two motion actions at the same time: Land"), std::string::npos)
      << r.text;
}

TEST(Checker, ReportsEveryErrorOfAFileInOneRun) {
  Result r = check(
      "var A Quad\nfunc INIT() {\n  B.Arm()\n  A.Fly()\n  A.Takeoff()\n  SEQ_missing()\n"
      "  If(A.X(), SEQ_x, SEQ_x)\n}\nfunc SEQ_x() { A.Arm() }\nfunc bad() {}\n");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.errors, 6u) << r.text;
}

TEST(Checker, BinaryGarbageIsReportedNotCrashed) {
  std::string garbage;
  for (int i = 0; i < 20000; ++i) garbage += static_cast<char>((i * 7919) % 256);
  Result r = check(garbage);
  EXPECT_FALSE(r.ok);
  EXPECT_GT(r.errors, 0u);
}

TEST(Checker, ExponentialExpansionIsRejectedBeforeBuildingIt) {
  // Each block calls the next twice: 2^40 instances if expanded.
  std::string text = "var A Quad\nfunc INIT() { SEQ_0() }\n";
  for (int i = 0; i < 40; ++i)
    text += "func SEQ_" + std::to_string(i) + "() { SEQ_" + std::to_string(i + 1) + "(); SEQ_" +
            std::to_string(i + 1) + "() }\n";
  text += "func SEQ_40() { A.Arm() }\n";
  Result r = check(text);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.text.find("mission expands to more than"), std::string::npos) << r.text;
}

TEST(Checker, VeryLongCallChainIsAnErrorNotAStackOverflow) {
  std::string text = "var A Quad\nfunc INIT() { SEQ_0() }\n";
  for (int i = 0; i < 50000; ++i)
    text += "func SEQ_" + std::to_string(i) + "() { SEQ_" + std::to_string(i + 1) + "() }\n";
  text += "func SEQ_50000() { A.Arm() }\n";
  Result r = check(text);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.text.find("nest more than"), std::string::npos);
}

TEST(Checker, MutualRecursionIsReportedOnce) {
  Result r = check("var A Quad\nfunc INIT() { SEQ_a() }\nfunc SEQ_a() { SEQ_b() }\nfunc SEQ_b() { If(true, SEQ_a, SEQ_a) }\n");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.errors, 1u) << r.text;
  EXPECT_NE(r.text.find("recursion"), std::string::npos);
}

TEST(Checker, ErrorCarriesFileLineColumnSourceLineAndAnUnderlinedToken) {
  Result r = check("var A Quad\nfunc INIT() {\n\tA.Tkeoff(3)\n}\n");
  EXPECT_EQ(r.text,
            "m.eamos:3:4: error: drone 'A' of type 'Quad' has no capability 'Tkeoff'; did you mean 'Takeoff'?\n"
            " \tA.Tkeoff(3)\n"
            " \t  ^~~~~~\n");
}
}  // namespace
}  // namespace eamos

namespace eamos {
namespace {

// Each of these repeat branches has to wait on every path, so the loop-time rule accepts it.
TEST(Checker, LoopsWhoseBodiesWaitOnEveryPathAreAccepted) {
  const char* bodies[] = {
      "Drone1.FlyByX(1)",
      "PauseFor(0.5)",
      "PauseUntil(Drone1.X() > 3)",
      "WaitUntil(Drone1.X() > 3, SEQ_none)",
      "PAR_both()",
      "If(Drone1.X() > 3, SEQ_fly, SEQ_pause)",
      "If(true, SEQ_fly, SEQ_none)",
      "RepeatFor(true, SEQ_fly, SEQ_none, 2)",
      "RepeatWhile(Drone1.X() > 3, SEQ_pause, SEQ_fly)",
      "DoWhileSync(true, SEQ_fly, SEQ_none)",
      "async(SEQ_fly)\n  Drone1.TakePicture()",
  };
  for (const char* body : bodies) {
    std::string text = std::string("var Drone1 Quad\nfunc INIT() {\n  Drone1.Takeoff(5)\n") +
                       "  RepeatWhile(Drone1.Z() > 1, SEQ_body, SEQ_none)\n  Drone1.Land()\n}\n" +
                       "func SEQ_body() {\n  " + body + "\n}\n" +
                       "func SEQ_fly() {Drone1.FlyByX(1)}\nfunc SEQ_pause() {PauseFor(1)}\n" +
                       "func SEQ_none() {}\nfunc PAR_both() {async(SEQ_fly)\n  Drone1.TakePicture()}\n";
    Result r = check(text);
    EXPECT_EQ(r.text.find("without mission time passing"), std::string::npos) << body << "\n" << r.text;
  }
}

// The rule runs beside the other checks, so one run lists a typo and a spinning loop.
TEST(Checker, SpinningLoopIsReportedTogetherWithOtherErrors) {
  Result r = check("var Drone1 Quad\nfunc INIT() {\n  Drone1.Takof(5)\n"
                   "  RepeatWhile(true, SEQ_r, SEQ_n)\n}\nfunc SEQ_r() {SEQ_e()}\n"
                   "func SEQ_e() {}\nfunc SEQ_n() {Drone1.Land()}\n");
  EXPECT_EQ(r.errors, 2u) << r.text;
  EXPECT_NE(r.text.find("m.eamos:4:3: error: RepeatWhile can repeat without mission time passing"),
            std::string::npos) << r.text;
}

// Recursion is its own error; the loop rule must neither loop for ever nor add a second one.
TEST(Checker, LoopRuleToleratesRecursiveBlocks) {
  Result r = check("var Drone1 Quad\nfunc INIT() {\n  RepeatWhile(true, SEQ_a, SEQ_n)\n}\n"
                   "func SEQ_a() {SEQ_b()}\nfunc SEQ_b() {SEQ_a()}\nfunc SEQ_n() {Drone1.Land()}\n");
  EXPECT_NE(r.text.find("recursion"), std::string::npos) << r.text;
  EXPECT_EQ(r.text.find("without mission time passing"), std::string::npos) << r.text;
}

/// A show: every drone in every step's PAR, arming first and flying once per step.
std::string show_mission(int drones, int steps) {
  std::string text, seq = "func INIT() { SEQ_show() }\nfunc SEQ_show() {\n";
  for (int d = 0; d < drones; ++d) text += "var D" + std::to_string(d) + " Quad\n";
  for (int s = 0; s < steps; ++s) {
    std::string par = "PAR_s" + std::to_string(s);
    seq += "  " + par + "()\n";
    text += "func " + par + "() {\n";
    for (int d = 0; d < drones; ++d) text += "  SEQ_" + std::to_string(d) + "_" + std::to_string(s) + "()\n";
    text += "}\n";
    for (int d = 0; d < drones; ++d) {
      std::string me = "D" + std::to_string(d);
      text += "func SEQ_" + std::to_string(d) + "_" + std::to_string(s) + "() { " +
              (s == 0 ? me + ".Arm(); " + me + ".Takeoff(3)" : me + ".FlyTo(1, 2, 3)") + " }\n";
    }
  }
  return text + seq + "}\n";
}

long long arming_work(int drones, int steps) {
  graph::Compilation c;
  Diagnostics d;
  EXPECT_TRUE(graph::compile(std::make_shared<SourceFile>("show.eamos", show_mission(drones, steps)), fleet::Fleet{},
                             d, c)) << d.format();
  Diagnostics again;
  long long work = 0;
  lang::check_armed_before_motion(c.mission, c.checked.drone_types, again, &work);
  EXPECT_EQ(again.warning_count() + again.error_count(), 0u) << again.format();
  return work;
}

// Each drone follows its own statements through every PAR, not its siblings': doubling the
// fleet of a show doubles the work. Following every sibling made a 1,000-drone show's check
// take minutes.
TEST(Checker, TheArmedStateRuleGrowsWithTheFleetNotWithItsSquare) {
  long long small = arming_work(20, 5), large = arming_work(40, 5);
  EXPECT_GT(small, 0);
  EXPECT_LE(large, 2 * small + 10) << "20 drones: " << small << " visits; 40 drones: " << large;
  // A PAR visits its drone's sibling twice (alone, then from what the others set).
  EXPECT_LE(large, 8 * 40 * 5) << "each drone visits a few times its own statements and the blocks leading to them";
}

// A drone's settings copy its type's whole catalogue; made per FlyTo, they were most of a
// 500,000-statement show's check.
TEST(Checker, TheAltitudeRuleMakesEachDronesSettingsOnceNotPerStatement) {
  graph::Compilation c;
  Diagnostics d;
  ASSERT_TRUE(graph::compile(std::make_shared<SourceFile>("show.eamos", show_mission(3, 20)), fleet::Fleet{}, d, c))
      << d.format();
  Diagnostics again;
  int made = 0;
  lang::check_literal_altitudes(c.mission, c.fleet, again, &made);
  EXPECT_EQ(again.error_count(), 0u) << again.format();
  EXPECT_EQ(made, 3) << "one per drone, not one per Takeoff or FlyTo (60 here)";
}

}  // namespace
}  // namespace eamos
