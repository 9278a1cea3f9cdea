// MDG construction (paper IV.C): forks cloned per drone, conditions held by one drone and
// seen by the others as external nodes, every cross-drone arc in both drones' MDGs.
#include <algorithm>

#include "helpers.h"

namespace eamos {
namespace {

using graph::MegKind;
using test::compile_text;
using test::node;

const char* kThree =
    "var A Quad\nvar B Quad\nvar C Quad\n"
    "func INIT() { PAR_arm(); PAR_go() }\n"
    "func PAR_arm() { A.Arm(); B.Arm(); C.Arm() }\n"
    "func PAR_go() { SEQ_a(); SEQ_b() }\n"
    "func SEQ_a() { A.Takeoff(3) }\n"
    "func SEQ_b() { WaitUntil(A.Z() > 2, SEQ_bw) }\n"
    "func SEQ_bw() { B.Takeoff(3) }\n";

TEST(Mdg, ForkIsClonedOntoEachDroneItStarts) {
  auto c = compile_text(kThree);
  ASSERT_TRUE(c);
  int fork = node(*c, "fork PAR_go");
  // PAR_go starts A's takeoff and the WaitUntil, which A evaluates (it reads A.Z()).
  EXPECT_GE(c->mdgs[0].find(fork, 0), 0);
  EXPECT_LT(c->mdgs[1].find(fork, 1), 0);
  EXPECT_LT(c->mdgs[2].find(fork, 2), 0);
  int arm_fork = node(*c, "fork PAR_arm");
  for (int d = 0; d < 3; ++d) EXPECT_GE(c->mdgs[d].find(arm_fork, d), 0) << d;
}

TEST(Mdg, DroneWithoutACloneAnnouncesItsArrivalThroughOneExternalCopy) {
  auto c = compile_text(kThree);
  ASSERT_TRUE(c);
  int fork = node(*c, "fork PAR_go");
  int b_arm = node(*c, "B.Arm()");
  const graph::Mdg& b = c->mdgs[1];
  int from = b.find(b_arm, 1), to = b.find(fork, 0);
  ASSERT_GE(from, 0);
  ASSERT_GE(to, 0);
  EXPECT_FALSE(b.nodes[to].internal);
  ASSERT_GE(b.nodes[to].notify, 0);
  EXPECT_EQ(b.drone_sets[b.nodes[to].notify], std::vector<int>{0});  // A holds the only clone
  bool found = false;
  for (const auto& a : b.arcs) found |= a.from == from && a.to == to;
  EXPECT_TRUE(found);
  // A's clone waits for B and C, and holds no copy of their Arm nodes.
  const graph::Mdg& a = c->mdgs[0];
  int clone = a.find(fork, 0);
  ASSERT_GE(a.nodes[clone].waits, 0);
  EXPECT_EQ(a.drone_sets[a.nodes[clone].waits], (std::vector<int>{0, 1, 2}));
  EXPECT_LT(a.find(b_arm, 1), 0);
}

TEST(Mdg, ConditionIsInternalToItsEvaluatorAndExternalToFollowers) {
  auto c = compile_text(kThree);
  ASSERT_TRUE(c);
  int cond = node(*c, "WaitUntil A.Z() > 2");
  ASSERT_EQ(c->meg.nodes[cond].drone, 0);
  int in_a = c->mdgs[0].find(cond, 0), in_b = c->mdgs[1].find(cond, 0);
  ASSERT_GE(in_a, 0);
  ASSERT_GE(in_b, 0);
  EXPECT_TRUE(c->mdgs[0].nodes[in_a].internal);
  EXPECT_FALSE(c->mdgs[1].nodes[in_b].internal);
  EXPECT_EQ(c->mdgs[1].nodes[in_b].drone, 0);  // B follows A's outcome
  EXPECT_LT(c->mdgs[2].find(cond, 0), 0);      // C has nothing to do with it
}

TEST(Mdg, EveryMegArcIsInTheMdgOfBothEndsOrIsABarrierArrival) {
  auto c = compile_text(kThree);
  ASSERT_TRUE(c);
  auto clones = graph::sync_clones(c->meg);
  auto has_arc = [](const graph::Mdg& g, int f, int t, graph::ArcKind kind) {
    for (const auto& m : g.arcs)
      if (m.from == f && m.to == t && m.kind == kind) return true;
    return false;
  };
  for (const auto& a : c->meg.arcs) {
    const auto& u = c->meg.nodes[a.from];
    const auto& v = c->meg.nodes[a.to];
    bool su = graph::is_sync_point(u.kind), sv = graph::is_sync_point(v.kind);
    if (sv && !su) {
      // Only on the predecessor's drone, into its own clone or one copy of the first holder's.
      const graph::Mdg& g = c->mdgs[u.drone];
      bool holds = std::count(clones[v.id].begin(), clones[v.id].end(), u.drone) > 0;
      int t = g.find(v.id, holds ? u.drone : clones[v.id].front());
      EXPECT_TRUE(has_arc(g, g.find(u.id, u.drone), t, a.kind)) << "arrival arc n" << a.from << "->n" << a.to;
      for (int k : clones[v.id]) {
        const graph::Mdg& h = c->mdgs[k];
        if (k == u.drone) continue;
        const auto& clone = h.nodes[h.find(v.id, k)];
        ASSERT_GE(clone.waits, 0) << "clone of n" << v.id << " on drone " << k;
        const auto& set = h.drone_sets[clone.waits];
        EXPECT_TRUE(std::binary_search(set.begin(), set.end(), u.drone));
      }
      continue;
    }
    std::vector<std::pair<int, int>> pairs;  // (from holder, to holder)
    if (!sv) pairs.push_back({su ? v.drone : u.drone, v.drone});
    else
      for (int k : clones[v.id]) pairs.push_back({k, k});
    for (auto [du, dv] : pairs)
      for (int holder : {du, dv}) {
        const graph::Mdg& g = c->mdgs[holder];
        EXPECT_TRUE(has_arc(g, g.find(u.id, du), g.find(v.id, dv), a.kind))
            << "arc n" << a.from << "->n" << a.to << " missing in MDG of drone " << holder;
      }
  }
}

TEST(Mdg, FleetWideBarrierCostsArcsLinearInTheFleetAndOneSharedDroneSet) {
  const int k = 40;
  std::string text;
  for (int d = 0; d < k; ++d) text += "var D" + std::to_string(d) + " Quad\n";
  text += "func INIT() { PAR_arm(); PAR_up(); PAR_land() }\n";
  for (const char* par : {"arm", "up", "land"}) {
    text += std::string("func PAR_") + par + "() {";
    for (int d = 0; d < k; ++d)
      text += " D" + std::to_string(d) + (std::string(par) == "arm" ? ".Arm();" : std::string(par) == "up" ? ".Takeoff(3);" : ".Land();");
    text += " }\n";
  }
  auto c = compile_text(text);
  ASSERT_TRUE(c);
  std::size_t arcs = 0;
  for (const auto& g : c->mdgs) {
    arcs += g.arcs.size();
    EXPECT_EQ(g.drone_sets.size(), 1u) << "drone " << g.drone;  // every barrier: all drones
    // The lead holds the mission end, which every drone's last node triggers.
    EXPECT_LE(g.nodes.size(), g.drone == 0 ? 8u + k : 8u) << "drone " << g.drone;
  }
  // Per drone: init → fork → Arm → fork → Takeoff → fork → Land, and Land → end.
  EXPECT_LE(arcs, static_cast<std::size_t>(8 * k));
}

TEST(Mdg, DoConditionListsTheNodesItCancelsOnEachDrone) {
  auto c = compile_text(
      "var A Quad\nvar B Quad\n"
      "func INIT() { PAR_arm(); DoWhileSync(A.Battery() > 30, PAR_do, SEQ_done) }\n"
      "func PAR_arm() { A.Arm(); B.Arm() }\n"
      "func PAR_do() { A.Orbit(); B.Orbit() }\nfunc SEQ_done() { A.Land() }\n");
  ASSERT_TRUE(c);
  int cond = node(*c, "DoWhileSync A.Battery() > 30");
  int b_orbit = node(*c, "B.Orbit()");
  const graph::Mdg& b = c->mdgs[1];
  int cond_in_b = b.find(cond, 0);
  ASSERT_GE(cond_in_b, 0);
  std::span<const int> cancels = b.cancels(cond_in_b);
  EXPECT_NE(std::find(cancels.begin(), cancels.end(), b.find(b_orbit, 1)), cancels.end());
}

TEST(Mdg, MissionEndIsHeldByTheFirstDrone) {
  auto c = compile_text(kThree);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->meg.nodes[c->meg.end].drone, 0);
  EXPECT_TRUE(c->mdgs[0].nodes[c->mdgs[0].find(c->meg.end, 0)].internal);
}

TEST(Mdg, DroneRecordsWhoseTelemetryItReads) {
  auto c = compile_text(
      "var A Quad\nvar B Quad\nfunc INIT() { A.Arm(); B.Arm(); B.FlyByX(A.X()) }\n");
  ASSERT_TRUE(c);
  EXPECT_EQ(c->mdgs[1].reads, std::vector<int>{0});
  EXPECT_TRUE(c->mdgs[0].reads.empty());
}

}  // namespace
}  // namespace eamos
