// `eamos dex`, `eamos launch` and `eamos run --distributed`: the mission as separate
// processes, one DEX per drone, over Cyclone DDS (src/launch).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/progress.h"
#include "deploy/mission_file.h"
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

namespace {

/// Every drone's mission of the deployment in `dir`, for the terminal's status lines; empty
/// when one cannot be read (the ground reports that itself, and the plain log is shown).
std::vector<dex::Mission> deployed_missions(const std::string& dir) {
  std::vector<dex::Mission> missions;
  std::ifstream in(dir + "/manifest.json");
  nlohmann::json manifest = nlohmann::json::parse(in, nullptr, false);
  if (!manifest.is_object() || !manifest.contains("drones") || !manifest["drones"].is_array()) return {};
  for (const nlohmann::json& d : manifest["drones"]) {
    if (!d.is_object() || !d.contains("folder") || !d["folder"].is_string()) return {};
    dex::Mission m;
    std::vector<std::string> defects;
    if (!deploy::read_mission_file(dir + "/" + d["folder"].get<std::string>() + "/mission.json", m, defects)) return {};
    missions.push_back(std::move(m));
  }
  return missions;
}

}  // namespace

int cmd_launch(const launch::LaunchOptions& options, const RunCommandOptions& r) {
  if (options.insecure) warn_insecure("launch");
  dex::LiveLog live(std::cout);
  std::unique_ptr<ProgressDisplay> progress;
  if (r.log && stdout_is_terminal()) {
    std::vector<dex::Mission> missions = deployed_missions(options.dir);
    if (!missions.empty()) progress = std::make_unique<ProgressDisplay>(std::cout, missions);
  }
  dex::TraceSink* shown = progress ? static_cast<dex::TraceSink*>(progress.get()) : &live;
  launch::LaunchResult result;
  launch::LaunchOptions with_rate = options;
  with_rate.telemetry_hz = r.telemetry_hz;
  int status = launch::launch(with_rate, r.log ? shown : nullptr, result, std::cout, std::cerr);
  if (progress) progress->finish();
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
