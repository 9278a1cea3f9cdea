// Small-scale checks of the shapes `make bench` measures at a thousand drones: each
// generated shape compiles clean and flies to completion, and what a barrier costs grows
// with the fleet, not with its square (docs/architecture.md, "A sync point is a barrier
// that costs O(k)"; docs/performance.md has the figures at scale).
#include <gtest/gtest.h>

#include "flight.h"
#include "stress/generator.h"

namespace eamos {
namespace {

std::string generated(stress::Shape shape, int drones, long long nodes) {
  stress::StressOptions o;
  o.shape = shape;
  o.drones = drones;
  o.target_nodes = nodes;
  o.work_per_step = 1;
  return stress::generate_mission(o);
}

/// MDG arcs and external nodes over every drone's mission file, and the messages a run sends.
struct Cost {
  std::size_t arcs = 0;
  std::size_t external_nodes = 0;
  std::size_t messages = 0;
};

Cost cost_of(const std::string& text) {
  Cost c;
  std::vector<dex::Mission> missions = test::missions_of(text);
  for (const dex::Mission& m : missions) {
    c.arcs += m.arcs.size();
    for (const dex::Node& n : m.nodes) c.external_nodes += n.internal ? 0 : 1;
  }
  test::Flight f = test::fly_missions(std::move(missions));
  EXPECT_TRUE(f.result.completed) << f.result.error;
  for (const dex::TraceEvent& e : f.events) c.messages += e.event == "message" ? 1 : 0;
  return c;
}

TEST(Scale, EveryGeneratedShapeCompilesAndFliesToCompletion) {
  for (stress::Shape shape : {stress::Shape::squads, stress::Shape::show, stress::Shape::cross}) {
    test::Flight f = test::fly(generated(shape, 24, 1500));
    EXPECT_TRUE(f.result.completed) << stress::shape_name(shape) << ": " << f.result.error;
  }
}

// A show doubles its fleet at the same number of barriers: the files' arcs and external
// nodes double too (the paper's all-to-all design would quadruple them); the messages
// delivered in one process are k - 1 per arrival, so they grow as k², and the files do not.
TEST(Scale, AShowsMissionFilesGrowLinearlyWithItsFleet) {
  Cost small = cost_of(generated(stress::Shape::show, 16, 16 * 6));
  Cost large = cost_of(generated(stress::Shape::show, 32, 32 * 6));
  ASSERT_GT(small.arcs, 0u);
  EXPECT_LE(large.arcs, small.arcs * 2 + 8) << small.arcs << " -> " << large.arcs;
  EXPECT_LE(large.external_nodes, small.external_nodes * 2 + 8)
      << small.external_nodes << " -> " << large.external_nodes;
  EXPECT_GT(large.messages, small.messages * 3) << "arrivals reach every other drone";
}

}  // namespace
}  // namespace eamos
