// The logic analysis (src/graph/static_checks.cpp) must never claim what a flight can
// disprove: each test here is a mission where a wait or a branch *can* go either way, and
// the check must stay silent about it; and a few where one instance of a block decides the
// verdict. The diagnostics each rule prints are golden files in tests/lang/diagnostics/logic_*.
#include <gtest/gtest.h>

#include "graph/pipeline.h"
#include "graph/static_checks.h"
#include "helpers.h"

namespace eamos {
namespace {

struct Checked {
  bool ok = false;
  std::string text;
};

Checked check(const std::string& body, const std::string& fleet_text = "") {
  fleet::Fleet fleet;
  Diagnostics diags;
  if (!fleet_text.empty()) {
    EXPECT_TRUE(fleet::parse_fleet(std::make_shared<SourceFile>("f.yaml", fleet_text), fleet, diags)) << diags.format();
  }
  graph::Compilation c;
  std::string text = "var A Quad\nvar B Quad\n" + body;
  Checked r;
  r.ok = graph::compile(std::make_shared<SourceFile>("m.eamos", text), fleet, diags, c);
  r.text = diags.format();
  return r;
}

bool silent(const Checked& r) { return r.ok && r.text.empty(); }

TEST(StaticChecks, WaitInADoBranchIsNotAnErrorBecauseTheDoMayCancelIt) {
  Checked r = check(
      "func INIT() { A.Arm(); A.Takeoff(5); DoWhileSync(A.Battery() > 50, SEQ_do, SEQ_done); A.Land(); A.Disarm() }\n"
      "func SEQ_do() { WaitUntil(B.Z() > 3, SEQ_x) }\nfunc SEQ_x() { A.TakePicture() }\n"
      "func SEQ_done() { A.Hover(1) }\n");
  EXPECT_TRUE(silent(r)) << r.text;
}

TEST(StaticChecks, DroneThatLandsOnOneBranchOnlyIsNotKnownToHaveLanded) {
  Checked r = check(
      "func INIT() { A.Arm(); A.Takeoff(5); If(A.Battery() > 50, SEQ_down, SEQ_stay); WaitUntil(A.Z() > 4, SEQ_x); "
      "A.Land(); A.Disarm() }\n"
      "func SEQ_down() { A.Land() }\nfunc SEQ_stay() { A.Hover(1) }\nfunc SEQ_x() { A.TakePicture() }\n");
  EXPECT_TRUE(silent(r)) << r.text;
}

TEST(StaticChecks, DroneThatMayTakeOffAgainMeanwhileIsNotKnownToHaveLanded) {
  Checked r = check(
      "func INIT() { A.Arm(); A.Takeoff(5); A.Land(); PAR_x(); A.Disarm() }\n"
      "func PAR_x() { PauseUntil(A.Z() > 4); SEQ_up() }\nfunc SEQ_up() { A.Takeoff(5); A.Land() }\n");
  EXPECT_TRUE(silent(r)) << r.text;
}

TEST(StaticChecks, WaitOnAPositionThatOtherActionsPrecedeIsNotDecided) {
  // B takes off in a loop body that runs before the wait: the loop condition's first run
  // does not wait for its body, but the wait after the loop does.
  Checked r = check(
      "func INIT() { B.Arm(); RepeatFor(B.Battery() > 0, SEQ_up, SEQ_after, 1); A.Disarm() }\n"
      "func SEQ_up() { B.Takeoff(5) }\nfunc SEQ_after() { PauseUntil(B.Z() > 4); B.Land(); B.Disarm() }\n");
  EXPECT_TRUE(silent(r)) << r.text;
}

TEST(StaticChecks, BatteryAndSensorsWithoutARangeAreNeverDecided) {
  Checked r = check(
      "func INIT() { A.Arm(); A.Takeoff(5); WaitUntil(A.Battery() > 200 || B.Sensor1() < -5, SEQ_x); A.Land(); A.Disarm() }\n"
      "func SEQ_x() { A.TakePicture() }\n");
  EXPECT_TRUE(silent(r)) << r.text;
}

TEST(StaticChecks, PositionAcrossTheGroundOfADroneWithoutADeclaredHomeIsUnknown) {
  Checked r = check("func INIT() { A.Arm(); A.Takeoff(5); PauseUntil(B.X() > 100); A.Land(); A.Disarm() }\n");
  EXPECT_TRUE(silent(r)) << r.text;
  Checked declared = check("func INIT() { A.Arm(); A.Takeoff(5); PauseUntil(B.X() > 100); A.Land(); A.Disarm() }\n",
                           "drones:\n  B: {home: [0, 10, 0]}\n");
  EXPECT_FALSE(declared.ok);
  EXPECT_NE(declared.text.find("m.eamos:3:38: error: PauseUntil can never end"), std::string::npos) << declared.text;
}

TEST(StaticChecks, BranchIsDeadOnlyWhenItIsDeadInEveryCallOfItsBlock) {
  // SEQ_look's If is reached once with B on the ground and once with B in the air.
  Checked r = check(
      "func INIT() { A.Arm(); SEQ_look(); B.Arm(); B.Takeoff(5); SEQ_look(); B.Land(); B.Disarm(); A.Disarm() }\n"
      "func SEQ_look() { If(B.Landed(), SEQ_a, SEQ_b) }\nfunc SEQ_a() { A.TakePicture() }\nfunc SEQ_b() { A.TakePicture() }\n");
  EXPECT_TRUE(silent(r)) << r.text;
}

TEST(StaticChecks, WaitThatNeverEndsInOneCallOfItsBlockIsAnError) {
  Checked r = check(
      "func INIT() { A.Arm(); B.Arm(); B.Takeoff(5); SEQ_wait(); B.Land(); SEQ_wait(); B.Disarm(); A.Disarm() }\n"
      "func SEQ_wait() { PauseUntil(B.Z() > 3) }\n");
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.text.find("m.eamos:4:19: error: PauseUntil can never end"), std::string::npos) << r.text;
}

TEST(StaticChecks, BudgetSpentMeansNothingIsReportedRatherThanAGuess) {
  graph::Compilation c;
  Diagnostics diags;
  std::string text = "var A Quad\nvar B Quad\nfunc INIT() { A.Arm(); A.Takeoff(5); A.Land(); PauseUntil(A.Z() > 3) }\n";
  ASSERT_FALSE(graph::compile(std::make_shared<SourceFile>("m.eamos", text), fleet::Fleet{}, diags, c));
  // The same mission analysed again with no budget at all.
  Diagnostics quiet;
  graph::StaticCheckLimits none;
  none.max_node_visits = 0;
  graph::check_mission_logic({c.meg, c.mission, c.fleet, c.checked.drone_types, c.settings}, quiet, none);
  EXPECT_EQ(quiet.error_count(), 0u) << quiet.format();
}

// `eamos compile` frees every statement but the control structures before it builds the MEG:
// a finding still names the branch block, as a compile that keeps everything does.
TEST(StaticChecks, AFindingNamesItsBranchBlockWhenOnlyTheControlStatementsAreKept) {
  std::string text =
      "var Drone1 Quad\nvar Drone2 Quad\n"
      "func INIT() { Drone1.Arm(); Drone1.Takeoff(5); RepeatWhile(Drone2.Landed(), SEQ_photo, SEQ_after); "
      "Drone1.Land(); Drone1.Disarm() }\n"
      "func SEQ_photo() { Drone1.TakePicture(); PauseFor(1) }\n"
      "func SEQ_after() { Drone2.Arm(); Drone2.Takeoff(5); Drone2.Land(); Drone2.Disarm() }\n";
  std::string reports[2];
  graph::Keep keeps[2] = {graph::Keep::all_graphs, graph::Keep::deployment_graphs};
  for (int k = 0; k < 2; ++k) {
    graph::Compilation c;
    Diagnostics diags;
    EXPECT_FALSE(graph::compile(std::make_shared<SourceFile>("m.eamos", text), fleet::Fleet{}, diags, c, {}, keeps[k]));
    reports[k] = diags.format();
    if (keeps[k] != graph::Keep::deployment_graphs) continue;
    for (const lang::Function& f : c.mission.functions)
      for (const lang::Statement& s : f.body) EXPECT_NE(s.control, lang::ControlKind::none) << f.name << " " << s.callee;
  }
  EXPECT_NE(reports[1].find("whatever its body SEQ_photo does"), std::string::npos) << reports[1];
  EXPECT_EQ(reports[1], reports[0]);
}

}  // namespace
}  // namespace eamos
