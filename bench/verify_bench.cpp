// `eamos verify` performance: Listing 2 with every path its fleet allows (the If
// on Drone1's sensor both ways, with and without --jitter) under 100 ms, one path of the
// 5,000-node / 20-drone stress mission under 1 s, and the 100-drone missions: the squads'
// 64 paths (the default --paths) under 10 s, the show's one path well under. Each iteration
// verifies from the compiled mission files, as `eamos verify` does after compiling; the
// 100-drone ones take the number of flights flown at once as their argument (0: one per core).
#include <benchmark/benchmark.h>

#include "deploy/mission_file.h"
#include "graph/pipeline.h"
#include "stress/generator.h"
#include "verify/verify.h"

namespace {

struct Prepared {
  eamos::graph::Compilation c;
  std::vector<eamos::dex::Mission> missions;
};

std::unique_ptr<Prepared> prepare(const std::string& mission_path, const std::string& fleet_path,
                                  const std::string& text = "") {
  auto p = std::make_unique<Prepared>();
  eamos::Diagnostics diags;
  bool ok = text.empty() ? eamos::graph::compile_file(mission_path, fleet_path, diags, p->c)
                         : eamos::graph::compile(std::make_shared<eamos::SourceFile>("stress.eamos", text),
                                                 eamos::fleet::Fleet{}, diags, p->c);
  if (!ok) throw std::runtime_error(diags.format());
  std::string hash = eamos::deploy::mission_hash(p->c);
  p->missions.resize(p->c.drone_count());
  for (int d = 0; d < p->c.drone_count(); ++d) {
    std::vector<std::string> errors;
    if (!eamos::deploy::read_mission(eamos::deploy::mission_text(p->c, d, hash), "bench", p->missions[d], errors))
      throw std::runtime_error(errors.front());
  }
  return p;
}

void run(benchmark::State& state, const Prepared& p, eamos::verify::VerifyOptions o) {
  int paths = 0;
  for (auto _ : state) {
    eamos::verify::VerifyReport r = eamos::verify::verify(p.c, p.missions, o);
    paths = r.paths;
    benchmark::DoNotOptimize(r.violations.data());
  }
  state.counters["paths"] = paths;
}

void BM_VerifyListing2AllPaths(benchmark::State& state) {
  static auto p = prepare(EAMOS_SOURCE_DIR "/examples/listing2.eamos", EAMOS_SOURCE_DIR "/examples/listing2-range.yaml");
  eamos::verify::VerifyOptions o;
  o.jitter = state.range(0) != 0;
  run(state, *p, o);
}
BENCHMARK(BM_VerifyListing2AllPaths)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

void BM_VerifyStressOnePath(benchmark::State& state) {
  eamos::stress::StressOptions so;
  so.target_nodes = 5000;
  so.drones = 20;
  static auto p = prepare("", "", eamos::stress::generate_mission(so));
  eamos::verify::VerifyOptions o;
  o.max_paths = 1;
  run(state, *p, o);
}
BENCHMARK(BM_VerifyStressOnePath)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

std::unique_ptr<Prepared> hundred_drones(eamos::stress::Shape shape) {
  eamos::stress::StressOptions so;
  so.shape = shape;
  so.drones = 100;
  so.target_nodes = shape == eamos::stress::Shape::show ? 5200 : 10000;
  if (shape == eamos::stress::Shape::show) so.work_per_step = 1;
  return prepare("", "", eamos::stress::generate_mission(so));
}

void BM_VerifySquads100(benchmark::State& state) {
  static auto p = hundred_drones(eamos::stress::Shape::squads);
  eamos::verify::VerifyOptions o;
  o.jobs = static_cast<int>(state.range(0));
  run(state, *p, o);
}
BENCHMARK(BM_VerifySquads100)->Arg(1)->Arg(0)->Iterations(1)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

void BM_VerifyShow100(benchmark::State& state) {
  static auto p = hundred_drones(eamos::stress::Shape::show);
  run(state, *p, {});
}
BENCHMARK(BM_VerifyShow100)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
