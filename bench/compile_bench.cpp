// Mission Compiler performance, compared with the paper's Section VII: compiling Listing 2
// (paper: 50 ms, 4.4 MB) and a 5,000-node, 20-drone mission (paper: 2.34 s, 24 MB), plus
// the growth up to 500,000 nodes and 1,000 drones. "Compile" is the whole job of
// `eamos compile`: parse, check, AMT, MEG, MDGs, mission hash, manifest and every drone's
// mission file (written to a byte counter here, so the disk is not measured).
#include <benchmark/benchmark.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <streambuf>

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

/// An output stream that only counts the bytes written to it.
class ByteCounter : public std::streambuf {
 public:
  std::size_t bytes = 0;

 protected:
  std::streamsize xsputn(const char*, std::streamsize n) override {
    bytes += static_cast<std::size_t>(n);
    return n;
  }
  int_type overflow(int_type ch) override {
    ++bytes;
    return traits_type::not_eof(ch);
  }
};

void compile_or_throw(const std::string& text, eamos::graph::Compilation& c) {
  eamos::Diagnostics diags;
  if (!eamos::graph::compile(std::make_shared<eamos::SourceFile>("bench.eamos", text),
                             eamos::fleet::Fleet{}, diags, c))
    throw std::runtime_error("bench mission does not compile:\n" + diags.format());
}

/// What `eamos compile` does, in memory; returns the bytes of the deployment's files.
std::size_t compile_all(const std::string& text) {
  eamos::graph::Compilation c;
  compile_or_throw(text, c);
  std::string hash = eamos::deploy::mission_hash(c);
  ByteCounter counter;
  std::ostream out(&counter);
  out << eamos::deploy::manifest(c, hash).dump(2);
  for (int d = 0; d < c.drone_count(); ++d) eamos::deploy::write_drone_mission(out, c, d, hash);
  return counter.bytes;
}

/// A gen-stress mission; `shape` is a stress::Shape as a number (0 squads, 1 show, 2 cross).
std::string stress_mission(long long nodes, int drones, long long shape = 0) {
  eamos::stress::StressOptions o;
  o.target_nodes = nodes;
  o.drones = drones;
  o.shape = static_cast<eamos::stress::Shape>(shape);
  return eamos::stress::generate_mission(o);
}

void BM_CompileListing2(benchmark::State& state) {
  std::string text = read_file(std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos");
  for (auto _ : state) benchmark::DoNotOptimize(compile_all(text));
}
BENCHMARK(BM_CompileListing2)->Unit(benchmark::kMicrosecond);

// Args: nodes, drones, shape (0 squads, 1 show: every drone in every PAR, 2 cross: waits,
// Ifs and arguments on other squads' drones).
void BM_CompileStress(benchmark::State& state) {
  std::string text = stress_mission(state.range(0), static_cast<int>(state.range(1)), state.range(2));
  // The generator aims at a node count; per-node figures use the MEG's real size.
  double meg_nodes = 0;
  {
    eamos::graph::Compilation c;
    compile_or_throw(text, c);
    meg_nodes = static_cast<double>(c.meg.nodes.size());
  }
  for (auto _ : state) benchmark::DoNotOptimize(compile_all(text));
  state.counters["meg_nodes"] = meg_nodes;
  // Seconds per MEG node (shown with an SI prefix: "30ns").
  state.counters["time_per_node"] = benchmark::Counter(
      meg_nodes, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_CompileStress)
    ->ArgNames({"nodes", "drones", "shape"})
    ->Args({5000, 20, 0})
    ->Args({50000, 100, 0})
    ->Args({500000, 1000, 0})
    ->Args({50000, 100, 1})
    ->Args({500000, 1000, 1})
    ->Args({50000, 100, 2})
    ->Args({500000, 1000, 2})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

/// A finished run of the measured program: its peak resident memory and wall time.
struct ProcessRun {
  long peak_kib = -1;  ///< -1: it could not run or failed
  double seconds = 0;
};

/// Runs argv[0] with argv and measures it. Called in a freshly started process (see
/// below): Linux carries the peak of the process that forks over into the child's, so the
/// measurement must fork from something smaller than the program measured.
ProcessRun run_and_measure(char** argv) {
  auto start = std::chrono::steady_clock::now();
  pid_t pid = fork();
  if (pid == 0) {
    int devnull = open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    dup2(devnull, 2);
    execv(argv[0], argv);
    _exit(127);
  }
  int status = 0;
  struct rusage usage {};
  if (pid < 0 || wait4(pid, &status, 0, &usage) != pid) return {};
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return {};
  std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
  return {usage.ru_maxrss, elapsed.count()};
}

constexpr const char* kMeasureFlag = "--measure-peak-rss";

/// Whole-process time and peak memory of `eamos compile` (what the paper's numbers compare
/// with). The benchmark process has grown by the time this runs, and a child forked from it
/// would report that size as its own peak; so this re-executes the benchmark binary as a
/// small launcher (`--measure-peak-rss`), which starts eamos and prints its peak and its
/// wall time; the benchmark's time is that of eamos alone, without the launcher's start.
void BM_ProcessPeakRss(benchmark::State& state) {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / ("eamos-bench-" + std::to_string(getpid()));
  fs::create_directories(dir);
  std::string mission = std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos";
  if (state.range(0) > 0) {
    mission = (dir / "stress.eamos").string();
    std::ofstream(mission) << stress_mission(state.range(0), static_cast<int>(state.range(1)), state.range(2));
  }
  std::string self = fs::read_symlink("/proc/self/exe").string();
  std::string command = "'" + self + "' " + kMeasureFlag + " '" + EAMOS_BINARY + "' compile '" +
                        mission + "' -o '" + (dir / "out").string() + "' -q";
  long max_kib = 0;
  for (auto _ : state) {
    FILE* launcher = popen(command.c_str(), "r");
    ProcessRun run;
    if (!launcher || std::fscanf(launcher, "%ld %lf", &run.peak_kib, &run.seconds) != 2) run.peak_kib = -1;
    if (launcher) pclose(launcher);
    if (run.peak_kib < 0) {
      state.SkipWithError("eamos compile failed");
      break;
    }
    state.SetIterationTime(run.seconds);
    max_kib = std::max(max_kib, run.peak_kib);
  }
  state.counters["peak_rss_MB"] = static_cast<double>(max_kib) / 1024.0;
  fs::remove_all(dir);
}
BENCHMARK(BM_ProcessPeakRss)
    ->ArgNames({"nodes", "drones", "shape"})
    ->Args({0, 0, 0})
    ->Args({5000, 20, 0})
    ->Args({500000, 1000, 0})
    ->Args({500000, 1000, 1})
    ->Args({500000, 1000, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(3);

}  // namespace

int main(int argc, char** argv) {
  if (argc > 2 && std::strcmp(argv[1], kMeasureFlag) == 0) {
    ProcessRun run = run_and_measure(argv + 2);
    std::printf("%ld %.9f\n", run.peak_kib, run.seconds);
    return run.peak_kib < 0 ? 1 : 0;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
