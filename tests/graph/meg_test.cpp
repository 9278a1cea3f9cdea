// The MEG of each control structure, async and PAR/SEQ: which nodes exist and how they
// are wired. Each test compiles a minimal mission that uses one construct.
#include "helpers.h"

namespace eamos {
namespace {

using graph::ArcKind;
using graph::Branch;
using graph::MegKind;
using test::compile_text;
using test::has_arc;
using test::node;

const char* kHead = "var A Quad\nvar B Quad\n";

std::string mission(const std::string& body) { return std::string(kHead) + body; }

TEST(Meg, SequenceChainsActionsFromInitToEnd) {
  auto c = compile_text(mission("func INIT() {\n A.Arm()\n A.Takeoff(5)\n}\n"));
  ASSERT_TRUE(c);
  int arm = node(*c, "A.Arm()"), takeoff = node(*c, "A.Takeoff(5)");
  EXPECT_TRUE(has_arc(*c, c->meg.init, arm));
  EXPECT_TRUE(has_arc(*c, arm, takeoff));
  EXPECT_TRUE(has_arc(*c, takeoff, c->meg.end));
  EXPECT_EQ(c->meg.nodes.size(), 4u);
}

TEST(Meg, ParallelBlockForksAndNextStatementWaitsForEveryChild) {
  auto c = compile_text(mission(
      "func INIT() { PAR_arm(); A.Takeoff(5) }\nfunc PAR_arm() {\n A.Arm()\n B.Arm()\n}\n"));
  ASSERT_TRUE(c);
  int fork = node(*c, "fork PAR_arm");
  int a = node(*c, "A.Arm()"), b = node(*c, "B.Arm()"), t = node(*c, "A.Takeoff(5)");
  EXPECT_EQ(c->meg.nodes[fork].kind, MegKind::fork);
  EXPECT_TRUE(has_arc(*c, c->meg.init, fork));
  EXPECT_TRUE(has_arc(*c, fork, a));
  EXPECT_TRUE(has_arc(*c, fork, b));
  EXPECT_TRUE(has_arc(*c, a, t));
  EXPECT_TRUE(has_arc(*c, b, t));
  EXPECT_EQ(test::in_degree(*c, t), 2);
}

TEST(Meg, IfBranchesEndInTerminalsThatReleaseEachOther) {
  auto c = compile_text(mission(
      "func INIT() { If(A.Sensor1() > 3, SEQ_t, SEQ_f); B.Arm() }\n"
      "func SEQ_t() { A.Arm() }\nfunc SEQ_f() { A.Disarm() }\n"));
  ASSERT_TRUE(c);
  int cond = node(*c, "If A.Sensor1() > 3");
  int t = node(*c, "A.Arm()"), f = node(*c, "A.Disarm()");
  int tt = node(*c, "T then If"), tf = node(*c, "T else If");
  int next = node(*c, "B.Arm()");
  ASSERT_GE(cond, 0);
  EXPECT_TRUE(has_arc(*c, cond, t, ArcKind::exec, Branch::true_));
  EXPECT_TRUE(has_arc(*c, cond, f, ArcKind::exec, Branch::false_));
  EXPECT_TRUE(has_arc(*c, t, tt));
  EXPECT_TRUE(has_arc(*c, f, tf));
  EXPECT_TRUE(has_arc(*c, tt, tf, ArcKind::partner));
  EXPECT_TRUE(has_arc(*c, tf, tt, ArcKind::partner));
  EXPECT_TRUE(has_arc(*c, tt, next));
  EXPECT_TRUE(has_arc(*c, tf, next));
  EXPECT_EQ(c->meg.nodes[tt].owner_condition, cond);
}

TEST(Meg, WaitUntilStartsBranchOnGoAndEndsInTerminal) {
  for (const char* kind : {"WaitUntil", "WaitWhile"}) {
    auto c = compile_text(mission(std::string("func INIT() { ") + kind +
                                  "(A.X() >= 5, SEQ_w); B.Arm() }\nfunc SEQ_w() { B.Takeoff(2) }\n"));
    ASSERT_TRUE(c);
    int cond = node(*c, std::string(kind) + " A.X() >= 5");
    int w = node(*c, "B.Takeoff(2)"), t = node(*c, std::string("T wait ") + kind);
    EXPECT_TRUE(has_arc(*c, cond, w, ArcKind::exec, Branch::go)) << kind;
    EXPECT_TRUE(has_arc(*c, w, t)) << kind;
    EXPECT_TRUE(has_arc(*c, t, node(*c, "B.Arm()"))) << kind;
  }
}

TEST(Meg, RepeatLoopsBackFromRepeatTerminalToCondition) {
  for (const char* kind : {"RepeatUntil", "RepeatWhile"}) {
    auto c = compile_text(mission(std::string("func INIT() { A.Arm(); ") + kind +
                                  "(A.Z() > 9, SEQ_r, SEQ_n) }\nfunc SEQ_r() { A.FlyByZ(1) }\n"
                                  "func SEQ_n() { A.Land() }\n"));
    ASSERT_TRUE(c);
    int cond = node(*c, std::string(kind) + " A.Z() > 9");
    int r = node(*c, "A.FlyByZ(1)"), n = node(*c, "A.Land()");
    int tr = node(*c, std::string("T repeat ") + kind), tn = node(*c, std::string("T after ") + kind);
    EXPECT_TRUE(has_arc(*c, cond, r, ArcKind::exec, Branch::repeat));
    EXPECT_TRUE(has_arc(*c, r, tr));
    EXPECT_TRUE(has_arc(*c, tr, cond, ArcKind::back));
    EXPECT_TRUE(has_arc(*c, cond, n, ArcKind::exec, Branch::exit));
    EXPECT_TRUE(has_arc(*c, n, tn));
    EXPECT_TRUE(has_arc(*c, tn, c->meg.end));
  }
}

TEST(Meg, RepeatForCarriesItsIterationLimit) {
  auto c = compile_text(mission(
      "func INIT() { A.Arm(); RepeatFor(A.Z() < 9, SEQ_r, SEQ_n, 4) }\nfunc SEQ_r() { A.FlyByZ(1) }\n"
      "func SEQ_n() { A.Land() }\n"));
  ASSERT_TRUE(c);
  int cond = node(*c, "RepeatFor A.Z() < 9 ×4");
  ASSERT_GE(cond, 0);
  EXPECT_EQ(c->meg.nodes[cond].count, 4);
  EXPECT_TRUE(has_arc(*c, node(*c, "T repeat RepeatFor"), cond, ArcKind::back));
}

TEST(Meg, PauseUntilAndPauseWhileContinueOnGoWithoutTerminal) {
  for (const char* kind : {"PauseUntil", "PauseWhile"}) {
    auto c = compile_text(mission(std::string("func INIT() { A.Arm(); ") + kind +
                                  "(B.Battery() > 50); A.Takeoff(3) }\n"));
    ASSERT_TRUE(c);
    int cond = node(*c, std::string(kind) + " B.Battery() > 50");
    ASSERT_GE(cond, 0) << kind;
    EXPECT_EQ(c->meg.nodes[cond].drone, 1) << kind;  // B's property: B evaluates
    EXPECT_TRUE(has_arc(*c, node(*c, "A.Arm()"), cond)) << kind;
    EXPECT_TRUE(has_arc(*c, cond, node(*c, "A.Takeoff(3)"), ArcKind::exec, Branch::go)) << kind;
    EXPECT_TRUE(c->meg.terminals(cond).empty()) << kind;
  }
}

TEST(Meg, PauseForIsATimerOnTheDroneThatRanBefore) {
  auto c = compile_text(mission("func INIT() { B.Arm(); PauseFor(2.5); A.Arm() }\n"));
  ASSERT_TRUE(c);
  int p = node(*c, "PauseFor(2.5)");
  ASSERT_GE(p, 0);
  EXPECT_EQ(c->meg.nodes[p].kind, MegKind::pause);
  EXPECT_EQ(c->meg.nodes[p].seconds, 2.5);
  EXPECT_EQ(c->meg.nodes[p].drone, 1);
}

TEST(Meg, DoSyncCancelsDoBranchAndWaitsForOneOfItsTerminals) {
  for (const char* kind : {"DoUntilSync", "DoWhileSync"}) {
    auto c = compile_text(mission(std::string("func INIT() { A.Arm(); ") + kind +
                                  "(A.Battery() < 30, SEQ_do, SEQ_done); B.Arm() }\n"
                                  "func SEQ_do() { A.Orbit(); A.Hover(5) }\nfunc SEQ_done() { A.ReturnHome() }\n"));
    ASSERT_TRUE(c);
    int cond = node(*c, std::string(kind) + " A.Battery() < 30");
    int orbit = node(*c, "A.Orbit()"), hover = node(*c, "A.Hover(5)"), home = node(*c, "A.ReturnHome()");
    int tdo = node(*c, std::string("T do ") + kind), tdone = node(*c, std::string("T done ") + kind);
    int next = node(*c, "B.Arm()");
    EXPECT_TRUE(has_arc(*c, cond, orbit, ArcKind::exec, Branch::do_));
    EXPECT_TRUE(has_arc(*c, cond, tdo, ArcKind::partner, Branch::skip));
    EXPECT_TRUE(has_arc(*c, tdo, cond, ArcKind::stop));
    EXPECT_TRUE(has_arc(*c, cond, home, ArcKind::exec, Branch::done));
    EXPECT_TRUE(has_arc(*c, tdo, tdone, ArcKind::partner));
    EXPECT_TRUE(has_arc(*c, tdone, tdo, ArcKind::partner));
    EXPECT_TRUE(has_arc(*c, tdo, next));
    EXPECT_TRUE(has_arc(*c, tdone, next));
    std::span<const int> cancels = c->meg.cancels(cond);
    EXPECT_NE(std::find(cancels.begin(), cancels.end(), orbit), cancels.end());
    EXPECT_NE(std::find(cancels.begin(), cancels.end(), hover), cancels.end());
    EXPECT_EQ(std::find(cancels.begin(), cancels.end(), home), cancels.end());
  }
}

TEST(Meg, DoAsyncLetsTheSequenceContinueAtOnce) {
  for (const char* kind : {"DoUntilAsync", "DoWhileAsync"}) {
    auto c = compile_text(mission(std::string("func INIT() { A.Arm(); ") + kind +
                                  "(A.Battery() < 30, SEQ_do, SEQ_done); B.Arm() }\n"
                                  "func SEQ_do() { A.Orbit() }\nfunc SEQ_done() { A.Land() }\n"));
    ASSERT_TRUE(c);
    int cond = node(*c, std::string(kind) + " A.Battery() < 30");
    int next = node(*c, "B.Arm()");
    EXPECT_TRUE(has_arc(*c, cond, next, ArcKind::exec, Branch::continue_));
    EXPECT_EQ(test::in_degree(*c, next), 1);
    int tdo = node(*c, std::string("T do ") + kind);
    EXPECT_TRUE(c->meg.out(tdo).size() == 2u);  // stop + partner, no execution successor
  }
}

TEST(Meg, AsyncBlockStartsFromCallPointAndEndsInItsOwnTerminal) {
  auto c = compile_text(mission(
      "func INIT() { A.Arm(); async(SEQ_side); A.Takeoff(3) }\nfunc SEQ_side() { B.Sensor2() }\n"));
  ASSERT_TRUE(c);
  int arm = node(*c, "A.Arm()"), side = node(*c, "B.Sensor2()"), takeoff = node(*c, "A.Takeoff(3)");
  int t = node(*c, "T async SEQ_side");
  EXPECT_TRUE(has_arc(*c, arm, side));
  EXPECT_TRUE(has_arc(*c, arm, takeoff));
  EXPECT_TRUE(has_arc(*c, side, t));
  EXPECT_TRUE(c->meg.out(t).empty());
  EXPECT_EQ(test::in_degree(*c, c->meg.end), 1);
}

TEST(Meg, ConditionIsEvaluatedByTheDroneItReadsMost) {
  auto c = compile_text(mission(
      "func INIT() { If(A.X() > 1 && B.X() > 1 && B.Y() > 2, SEQ_t, SEQ_f) }\n"
      "func SEQ_t() { A.Arm() }\nfunc SEQ_f() { A.Disarm() }\n"));
  ASSERT_TRUE(c);
  int cond = node(*c, "If A.X() > 1 && B.X() > 1 && B.Y() > 2");
  EXPECT_EQ(c->meg.nodes[cond].drone, 1);
  EXPECT_EQ(c->meg.nodes[node(*c, "T then If")].drone, 1);
}

TEST(Meg, ConstantConditionIsEvaluatedByTheFirstDroneOfItsBranches) {
  auto c = compile_text(mission(
      "func INIT() { WaitUntil(true, SEQ_w) }\nfunc SEQ_w() { B.Arm() }\n"));
  ASSERT_TRUE(c);
  EXPECT_EQ(c->meg.nodes[node(*c, "WaitUntil true")].drone, 1);
}

TEST(Meg, EveryNodeCarriesItsSourcePosition) {
  auto c = compile_text(mission("func INIT() {\n  A.Arm()\n  PAR_x()\n}\nfunc PAR_x() {\n  B.Arm()\n}\n"));
  ASSERT_TRUE(c);
  for (const auto& n : c->meg.nodes) EXPECT_TRUE(n.loc.known()) << graph::meg_node_label(*c, n);
  EXPECT_EQ(c->meg.nodes[node(*c, "A.Arm()")].loc.line, 4);
  EXPECT_EQ(c->meg.nodes[node(*c, "A.Arm()")].loc.col, 3);
  EXPECT_EQ(c->meg.nodes[node(*c, "B.Arm()")].loc.line, 8);
}

}  // namespace
}  // namespace eamos
