// Mission Compiler performance, compared with the paper's Section VII: compiling Listing 2
// (paper: 50 ms, 4.4 MB) and a 5,000-node, 20-drone mission (paper: 2.34 s, 24 MB), plus
// the growth up to 500,000 nodes and 1,000 drones. "Compile" is the whole job of
// `eamos compile`: parse, check, AMT, MEG, MDGs, mission hash and every drone's JSON.
#include <benchmark/benchmark.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "deploy/synthesize.h"
#include "graph/pipeline.h"
#include "stress/generator.h"

namespace {

std::string read_file(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Compiles and synthesises every drone's mission file in memory; returns bytes written.
std::size_t compile_all(const std::string& text) {
  eamos::graph::Compilation c;
  eamos::Diagnostics diags;
  if (!eamos::graph::compile(std::make_shared<eamos::SourceFile>("bench.eamos", text),
                             eamos::fleet::Fleet{}, diags, c))
    throw std::runtime_error("bench mission does not compile:\n" + diags.format());
  std::string hash = eamos::deploy::mission_hash(c);
  std::size_t bytes = 0;
  for (int d = 0; d < c.drone_count(); ++d) bytes += eamos::deploy::drone_mission(c, d, hash).dump(1).size();
  return bytes;
}

void BM_CompileListing2(benchmark::State& state) {
  std::string text = read_file(std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos");
  for (auto _ : state) benchmark::DoNotOptimize(compile_all(text));
}
BENCHMARK(BM_CompileListing2)->Unit(benchmark::kMicrosecond);

void BM_CompileStress(benchmark::State& state) {
  eamos::stress::StressOptions o;
  o.target_nodes = state.range(0);
  o.drones = static_cast<int>(state.range(1));
  std::string text = eamos::stress::generate_mission(o);
  for (auto _ : state) benchmark::DoNotOptimize(compile_all(text));
  state.counters["nodes"] = static_cast<double>(o.target_nodes);
  state.counters["ns_per_node"] = benchmark::Counter(
      static_cast<double>(o.target_nodes), benchmark::Counter::kIsIterationInvariantRate |
                                               benchmark::Counter::kInvert);
}
BENCHMARK(BM_CompileStress)
    ->Args({5000, 20})
    ->Args({50000, 100})
    ->Args({500000, 1000})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

/// Whole-process peak memory of `eamos compile` (what the paper's pprof numbers compare
/// with): runs the real binary and reads ru_maxrss of the child.
void BM_ProcessPeakRss(benchmark::State& state) {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / ("eamos-bench-" + std::to_string(getpid()));
  fs::create_directories(dir);
  std::string mission = std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos";
  if (state.range(0) > 0) {
    eamos::stress::StressOptions o;
    o.target_nodes = state.range(0);
    o.drones = static_cast<int>(state.range(1));
    mission = (dir / "stress.eamos").string();
    std::ofstream(mission) << eamos::stress::generate_mission(o);
  }
  long max_kb = 0;
  for (auto _ : state) {
    pid_t pid = fork();
    if (pid == 0) {
      int devnull = open("/dev/null", O_WRONLY);
      dup2(devnull, 1);
      dup2(devnull, 2);
      execl(EAMOS_BINARY, EAMOS_BINARY, "compile", mission.c_str(), "-o", (dir / "out").c_str(), "-q",
            static_cast<char*>(nullptr));
      _exit(127);
    }
    int status = 0;
    struct rusage usage {};
    wait4(pid, &status, 0, &usage);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) state.SkipWithError("eamos compile failed");
    max_kb = std::max(max_kb, usage.ru_maxrss);
  }
  state.counters["peak_rss_MB"] = static_cast<double>(max_kb) / 1024.0;
  fs::remove_all(dir);
}
BENCHMARK(BM_ProcessPeakRss)
    ->Args({0, 0})
    ->Args({5000, 20})
    ->Args({500000, 1000})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
