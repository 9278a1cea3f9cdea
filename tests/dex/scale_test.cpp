// Small-scale checks of the shapes `make bench` measures at a thousand drones: each
// generated shape compiles clean and flies to completion, and what a barrier costs grows
// with the fleet, not with its square (docs/architecture.md, "A sync point is a barrier
// that costs O(k)"; docs/performance.md has the figures at scale).
#include <gtest/gtest.h>
#include <malloc.h>

#include <sstream>

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

/// Keeps every event but the messages, as `eamos run` without --trace: the run then counts
/// a barrier's arrivals itself instead of delivering each to every engine.
struct AllButMessages : dex::TraceSink {
  std::vector<std::string> events;
  void record(const dex::TraceEvent& e) override {
    std::ostringstream line;
    line << e.t << ' ' << e.drone << ' ' << e.event << ' ' << e.name << ' ' << e.node << ' ' << e.instance << ' '
         << e.outcome << ' ' << e.branch << ' ' << e.reason;
    events.push_back(line.str());
  }
  bool takes_messages() const override { return false; }
};

std::vector<std::string> without_messages(const test::Flight& f) {
  AllButMessages kept;
  for (const dex::TraceEvent& e : f.events)
    if (e.event != "message") kept.record(e);
  return kept.events;
}

// The same actions, nodes and barrier passes at the same instants and in the same order,
// whether or not a sink keeps the messages: shapes whose barriers are outside every loop
// (counted by the run) and examples whose barriers are inside Repeats and Dos (delivered).
TEST(Scale, ARunWithoutMessagesPassesEveryBarrierAsARunThatTracesThem) {
  std::vector<std::string> missions = {generated(stress::Shape::show, 24, 24 * 8),
                                       generated(stress::Shape::squads, 30, 1500),
                                       generated(stress::Shape::cross, 30, 1500), test::example("survey.eamos"),
                                       test::example("relay.eamos"), test::example("patrol.eamos")};
  for (const std::string& text : missions) {
    test::Flight traced = test::fly(text);
    mid::AdapterRegistry adapters;
    sim::register_adapter(adapters);
    AllButMessages sink;
    dex::RunOptions options;
    options.time_limit_s = 600;
    dex::RunResult r = dex::run_in_process(test::missions_of(text), adapters, &sink, options);
    EXPECT_TRUE(r.completed) << r.error;
    EXPECT_EQ(r.duration, traced.result.duration);
    EXPECT_EQ(sink.events, without_messages(traced)) << text.substr(0, 80);
  }
}

// Without a message trace, delivering an arrival looks only at the drones it must tell:
// a show's steps grow with its fleet (the barriers stay the same), not with its square. A
// look at the whole set per arrival would be 10⁸ steps per barrier of 10,000 drones.
TEST(Scale, AnUntracedBarrierLooksAtTheDronesItTellsNotAtItsWholeSet) {
  auto steps = [](int drones) {
    mid::AdapterRegistry adapters;
    sim::register_adapter(adapters);
    AllButMessages sink;
    dex::RunOptions options;
    options.time_limit_s = 600;
    dex::RunResult r = dex::run_in_process(test::missions_of(generated(stress::Shape::show, drones, drones * 6)),
                                           adapters, &sink, options);
    EXPECT_TRUE(r.completed) << r.error;
    return r.set_delivery_steps;
  };
  std::uint64_t small = steps(16), large = steps(64);
  ASSERT_GT(small, 0u);
  EXPECT_LE(large, small * 6) << small << " -> " << large << " steps for 4 times the drones";
}

// Missions loaded each on its own (no shared deploy::FleetTables: each holds its own copy of a barrier's
// drone set, as a program embedding the runner may load them) pass their barriers as shared
// ones do: the second copy of a set to reach a barrier turns it to delivering every arrival,
// and an arrival sent before that is delivered too, not counted where no engine hears of it
// (the show hung at its first barrier until its time limit).
TEST(Scale, MissionsThatShareNoTablesPassTheirBarriersAsSharedOnesDo) {
  std::string text = generated(stress::Shape::show, 12, 12 * 6);
  graph::Compilation c;
  Diagnostics diags;
  ASSERT_TRUE(graph::compile(std::make_shared<SourceFile>("t.eamos", text), fleet::Fleet{}, diags, c));
  std::vector<dex::Mission> missions(c.drone_count());
  for (int d = 0; d < c.drone_count(); ++d) {
    std::vector<std::string> errors;
    ASSERT_TRUE(deploy::read_mission(deploy::mission_text(c, d, deploy::mission_hash(c)), "m", missions[d], errors));
  }
  mid::AdapterRegistry adapters;
  sim::register_adapter(adapters);
  dex::RunOptions options;
  options.time_limit_s = 600;
  dex::RunResult alone = dex::run_in_process(missions, adapters, nullptr, options);
  dex::RunResult shared = dex::run_in_process(test::missions_of(text), adapters, nullptr, options);
  EXPECT_TRUE(alone.completed) << alone.error;
  EXPECT_TRUE(shared.completed) << shared.error;
  EXPECT_EQ(alone.duration, shared.duration);
  EXPECT_EQ(alone.activations, shared.activations);
}

/// Bytes the process holds in malloc's blocks now.
std::size_t held_bytes() {
  struct mallinfo2 i = mallinfo2();
  return i.uordblks + i.hblkhd;
}

// Every drone's file names the whole fleet and carries its fleet-wide drone sets: loaded as
// `eamos run` loads them, the missions of one process hold each such table once, so what
// they hold grows with the fleet and the nodes, not with the fleet's square (unshared, the
// names alone would be 32 bytes × 500 per drone here, beside about 13 KB of its own).
TEST(Scale, FiveHundredDronesMissionsHoldTheFleetsNamesAndSetsOnce) {
  std::string text = generated(stress::Shape::show, 500, 2000);
  std::size_t before = held_bytes();
  std::vector<dex::Mission> missions = test::missions_of(text);
  std::size_t per_drone = (held_bytes() - before) / 500;
  ASSERT_EQ(missions.size(), 500u);
  for (const dex::Mission& m : missions) {
    ASSERT_TRUE(m.fleet.same_as(missions[0].fleet)) << m.fleet[m.self];
    ASSERT_EQ(m.drone_sets.size(), missions[0].drone_sets.size());
    for (std::size_t s = 0; s < m.drone_sets.size(); ++s) {
      if (m.drone_sets[s] == missions[0].drone_sets[s]) {
        EXPECT_TRUE(m.drone_sets[s].same_as(missions[0].drone_sets[s]));
      }
    }
  }
  EXPECT_LT(per_drone, 20u * 1024) << "bytes held per drone";
}

/// Bytes of mission text a process that loads the fleet from its texts (the Python module)
/// reads to load every drone of `text`.
std::size_t text_bytes_loaded(const std::string& text) {
  graph::Compilation c;
  Diagnostics diags;
  EXPECT_TRUE(graph::compile(std::make_shared<SourceFile>("show.eamos", text), {}, diags, c)) << diags.format();
  std::vector<dex::Mission> missions;
  std::vector<std::string> errors;
  std::size_t bytes = 0;
  EXPECT_TRUE(deploy::read_compiled_missions(c, missions, errors, &bytes)) << (errors.empty() ? "" : errors[0]);
  return bytes;
}

// Loading a show of twice the drones reads twice the text, not four times: were each drone's
// text to name the whole fleet, 10,000 drones would write, hash and parse 10⁸ names.
TEST(Scale, LoadingAFleetReadsTextLinearInItsDrones) {
  std::size_t small = text_bytes_loaded(generated(stress::Shape::show, 200, 200 * 4));
  std::size_t large = text_bytes_loaded(generated(stress::Shape::show, 400, 400 * 4));
  ASSERT_GT(small, 0u);
  EXPECT_LE(large, small * 2 + small / 50) << small << " -> " << large << " bytes";
}

}  // namespace
}  // namespace eamos
