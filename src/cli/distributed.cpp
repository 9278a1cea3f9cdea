// `eamos dex`, `eamos launch` and `eamos run --distributed`: the mission as separate
// processes, one DEX per drone, over Cyclone DDS (src/launch).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "cli/commands.h"
#include "deploy/synthesize.h"
#include "dex/trace_writers.h"
#include "launch/dex_process.h"
#include "launch/ground.h"
#include "mavlink_adapter/adapter.h"
#include "sim/sim_adapter.h"

namespace eamos::cli {

int cmd_dex(const launch::DexProcessOptions& options) {
  if (options.insecure) warn_insecure("dex");
  mid::AdapterRegistry adapters;
  sim::register_adapter(adapters);
  // A DEX process always runs on wall time (scaled by its --speed).
  mavlink_adapter::register_adapter(adapters, {.real_time = true, .speed = options.speed});
  return launch::run_dex_process(options, adapters, std::cout, std::cerr);
}

int cmd_launch(const launch::LaunchOptions& options, const RunCommandOptions& r) {
  if (options.insecure) warn_insecure("launch");
  dex::LiveLog live(std::cout);
  launch::LaunchResult result;
  launch::LaunchOptions with_rate = options;
  with_rate.telemetry_hz = r.telemetry_hz;
  int status = launch::launch(with_rate, r.log ? &live : nullptr, result, std::cout, std::cerr);
  if (!r.trace.empty()) {
    std::ofstream out(r.trace, std::ios::trunc);
    if (!out) {
      std::cerr << "eamos: error: cannot write trace '" << r.trace << "'\n";
      return 1;
    }
    dex::JsonlTrace jsonl(out, result.fleet);
    jsonl.write_header(result.header);
    for (const auto& e : result.events) jsonl.record(e);
  }
  if (!report_run(r, result.run, result.events)) return 1;
  return result.run.completed ? status : 1;
}

int cmd_run_distributed(const CommonOptions& o, const RunCommandOptions& r, launch::LaunchOptions options,
                        const SecurityOptions& security) {
  if (security.insecure) warn_insecure("run --distributed");
  graph::Compilation c;
  if (!compile_and_report(o, c)) return 1;
  std::string dir = options.dir;
  if (dir.empty()) {
    std::string pattern = (std::filesystem::temp_directory_path() / "eamos-run-XXXXXX").string();
    if (!mkdtemp(pattern.data())) {
      std::cerr << "eamos: error: cannot make a temporary deployment folder\n";
      return 1;
    }
    dir = pattern;
  }
  Diagnostics diags;
  if (!deploy::write_deployment(c, dir, diags)) {
    std::cerr << diags.format();
    return 1;
  }
  if (!write_security(c, dir, security)) return 1;
  std::cout << "deployment in " << dir << "\n";
  options.dir = dir;
  options.insecure = security.insecure;
  return cmd_launch(options, r);
}

}  // namespace eamos::cli
