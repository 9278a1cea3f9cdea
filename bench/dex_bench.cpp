// DEX performance beside the paper's Section VII: starting a drone's mission (paper:
// 917 ms for Listing 2's Drone1, 734 ms for the largest drone of the 5,000-node mission),
// engine throughput on virtual time, and simulated seconds per wall second.
#include <benchmark/benchmark.h>

#include <chrono>
#include <fstream>
#include <sstream>

#include "deploy/mission_file.h"
#include "dex/runner.h"
#include "graph/pipeline.h"
#include "sim/sim_adapter.h"
#include "stress/generator.h"

namespace {

std::string read_file(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Compiled {
  eamos::graph::Compilation c;
  std::vector<std::string> files;  ///< each drone's mission file text
};

std::unique_ptr<Compiled> compile(const std::string& text) {
  auto out = std::make_unique<Compiled>();
  eamos::Diagnostics diags;
  if (!eamos::graph::compile(std::make_shared<eamos::SourceFile>("bench.eamos", text),
                             eamos::fleet::Fleet{}, diags, out->c))
    throw std::runtime_error(diags.format());
  std::string hash = eamos::deploy::mission_hash(out->c);
  for (int d = 0; d < out->c.drone_count(); ++d)
    out->files.push_back(eamos::deploy::mission_text(out->c, d, hash));
  return out;
}

std::string stress_text() {
  eamos::stress::StressOptions o;
  o.target_nodes = 5000;
  o.drones = 20;
  return eamos::stress::generate_mission(o);
}

/// Setup as the paper measures "starting the mission for a drone": read the mission file
/// text and build the linked node structure.
void setup(benchmark::State& state, const std::string& file) {
  for (auto _ : state) {
    eamos::dex::Mission m;
    std::vector<std::string> errors;
    if (!eamos::deploy::read_mission(file, "bench", m, errors)) state.SkipWithError(errors.front().c_str());
    benchmark::DoNotOptimize(m.nodes.data());
  }
}

void BM_SetupListing2Drone1(benchmark::State& state) {
  auto c = compile(read_file(std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos"));
  setup(state, c->files[0]);
  state.counters["nodes"] = static_cast<double>(c->c.mdgs[0].nodes.size());
}
BENCHMARK(BM_SetupListing2Drone1)->Unit(benchmark::kMicrosecond);

void BM_SetupLargestDroneOf5000(benchmark::State& state) {
  auto c = compile(stress_text());
  std::size_t largest = 0;
  for (std::size_t d = 1; d < c->files.size(); ++d)
    if (c->c.mdgs[d].nodes.size() > c->c.mdgs[largest].nodes.size()) largest = d;
  setup(state, c->files[largest]);
  state.counters["nodes"] = static_cast<double>(c->c.mdgs[largest].nodes.size());
}
BENCHMARK(BM_SetupLargestDroneOf5000)->Unit(benchmark::kMicrosecond);

struct Totals {
  double activations = 0, simulated = 0, wall = 0;
};

/// Flies `missions` once per benchmark iteration and adds up what each flight did.
Totals fly_repeatedly(benchmark::State& state, const std::vector<eamos::dex::Mission>& missions,
                      const eamos::mid::AdapterRegistry& adapters) {
  Totals t;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    eamos::dex::RunResult r = eamos::dex::run_in_process(missions, adapters, nullptr);
    t.wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!r.completed) state.SkipWithError(r.error.c_str());
    t.activations += static_cast<double>(r.activations);
    t.simulated += r.duration;
  }
  return t;
}

/// Flies the whole 5,000-node, 20-drone mission in the simulator on virtual time.
void BM_Fly5000Nodes20Drones(benchmark::State& state) {
  auto c = compile(stress_text());
  std::vector<eamos::dex::Mission> missions(c->files.size());
  for (std::size_t d = 0; d < c->files.size(); ++d) {
    std::vector<std::string> errors;
    eamos::deploy::read_mission(c->files[d], "bench", missions[d], errors);
  }
  eamos::mid::AdapterRegistry adapters;
  eamos::sim::register_adapter(adapters);
  Totals t = fly_repeatedly(state, missions, adapters);
  double activations = t.activations, simulated = t.simulated, wall = t.wall;
  state.counters["activations_per_s"] = benchmark::Counter(activations / wall);
  state.counters["sim_s_per_wall_s"] = benchmark::Counter(simulated / wall);
  state.counters["mission_s"] = simulated / static_cast<double>(state.iterations());
}
BENCHMARK(BM_Fly5000Nodes20Drones)->Unit(benchmark::kMillisecond)->UseRealTime();

/// A drone show in one process, as `eamos run` flies it (separation kept, no trace): 200
/// drones, FlyTo after FlyTo between 26 fleet-wide barriers. Loading the mission files is
/// outside the timing; scripts/bench.sh times the whole `eamos run` process at 1,000 drones.
void BM_FlyShow200Drones(benchmark::State& state) {
  eamos::stress::StressOptions o;
  o.shape = eamos::stress::Shape::show;
  o.drones = 200;
  o.work_per_step = 1;
  o.target_nodes = 5200;
  auto c = compile(eamos::stress::generate_mission(o));
  std::vector<eamos::dex::Mission> missions;
  std::vector<std::string> errors;  // as `eamos run` loads them: one fleet table, shared sets
  if (!eamos::deploy::read_compiled_missions(c->c, missions, errors)) throw std::runtime_error(errors.front());
  eamos::mid::AdapterRegistry adapters;
  eamos::sim::register_adapter(adapters);
  Totals t = fly_repeatedly(state, missions, adapters);
  state.counters["sim_s_per_wall_s"] = benchmark::Counter(t.simulated / t.wall);
  state.counters["mission_s"] = t.simulated / static_cast<double>(state.iterations());
}
BENCHMARK(BM_FlyShow200Drones)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The engine alone, no physics: a RepeatFor whose body is a millisecond's pause, so every
/// activation is the engine's own work (condition, pause timer, terminal, back arc). Not a
/// zero-second one: the checker refuses a loop that can repeat without mission time passing,
/// and on virtual time a millisecond costs no more than nothing.
void BM_EngineActivations(benchmark::State& state) {
  auto c = compile("var A Quad\nfunc INIT() { A.Arm(); RepeatFor(A.Armed(), SEQ_r, SEQ_n, 100000) }\n"
                   "func SEQ_r() { PauseFor(0.001) }\nfunc SEQ_n() { A.Disarm() }\n");
  std::vector<eamos::dex::Mission> missions(1);
  std::vector<std::string> errors;
  eamos::deploy::read_mission(c->files[0], "bench", missions[0], errors);
  eamos::mid::AdapterRegistry adapters;
  eamos::sim::register_adapter(adapters);
  Totals t = fly_repeatedly(state, missions, adapters);
  double activations = t.activations, wall = t.wall;
  state.counters["activations_per_s"] = benchmark::Counter(activations / wall);
  state.counters["activations"] = activations / static_cast<double>(state.iterations());
}
BENCHMARK(BM_EngineActivations)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
