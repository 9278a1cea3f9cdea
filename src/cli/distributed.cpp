// `eamos dex`, `eamos launch` and `eamos run --distributed`: the mission as separate
// processes, one DEX per drone, over Cyclone DDS (src/launch).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include <signal.h>
#include <unistd.h>

#include <cerrno>

#include <nlohmann/json.hpp>

#include "cli/arguments.h"
#include "cli/commands.h"
#include "cli/progress.h"
#include "deploy/manifest.h"
#include "deploy/mission_file.h"
#include "deploy/synthesize.h"
#include "dex/trace_writers.h"
#include "launch/dex_process.h"
#include "launch/ground.h"
#include "launch/stop_signals.h"
#include "mavlink_adapter/adapter.h"
#include "monitor/live_sink.h"
#include "monitor/server.h"
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
  deploy::DeploymentManifest manifest;
  std::string error;
  if (!deploy::read_manifest(dir, manifest, error)) return {};
  for (const deploy::DeployedDrone& d : manifest.drones) {
    dex::Mission m;
    std::vector<std::string> defects;
    if (!deploy::read_mission_file(dir + "/" + d.folder + "/mission.json", m, defects)) return {};
    missions.push_back(std::move(m));
  }
  return missions;
}

}  // namespace

int cmd_launch(const launch::LaunchOptions& options, const RunCommandOptions& r) {
  if (options.insecure) warn_insecure("launch");
  launch::LaunchOptions with_rate = options;
  with_rate.telemetry_hz = r.telemetry_hz;
  if (!r.monitor.empty()) return launch_with_monitor(with_rate, r);
  dex::LiveLog live(std::cout);
  std::unique_ptr<ProgressDisplay> progress;
  if (r.log && stdout_is_terminal()) {
    std::vector<dex::Mission> missions = deployed_missions(options.dir);
    if (!missions.empty()) progress = std::make_unique<ProgressDisplay>(std::cout, missions);
  }
  dex::TraceSink* shown = progress ? static_cast<dex::TraceSink*>(progress.get()) : &live;
  launch::LaunchResult result;
  int status = launch::launch(with_rate, r.log ? shown : nullptr, result, std::cout, std::cerr);
  if (progress) progress->finish();
  return report_launch(r, result, status);
}

namespace {

int g_hold_pipe[2] = {-1, -1};
void on_hold_signal(int) {
  char c = 1;
  (void)!write(g_hold_pipe[1], &c, 1);  // async-signal-safe; wakes the waiting read
}

// The ground handles the stop signals itself while it flies, and its DEX children inherit the
// signal mask, so no signal is blocked here: a handler wakes a pipe once the mission is over.
void hold_after_launch(monitor::MonitorServer& server) {
  if (pipe(g_hold_pipe) != 0) return;
  struct sigaction action {};
  action.sa_handler = on_hold_signal;
  sigemptyset(&action.sa_mask);
  for (int s : launch::stop_signals()) sigaction(s, &action, nullptr);
  server.finish();
  std::cout << "eamos: the mission has ended; the monitor shows it at " << server.url() << " until Ctrl-C\n"
            << std::flush;
  char c;
  while (read(g_hold_pipe[0], &c, 1) < 0 && errno == EINTR) {
  }
}

}  // namespace

// The ground's live events go to the log and to the page; after the end the page stays up.
int launch_with_monitor(const launch::LaunchOptions& options, const RunCommandOptions& r) {
  nlohmann::json view = launch_view(options.dir);
  monitor::MonitorServer server;
  if (!start_monitor(server, r.monitor, view)) return 1;
  std::cout << "eamos: monitor at " << server.url() << "\n" << std::flush;
  std::vector<dex::Mission> missions = deployed_missions(options.dir);
  monitor::LiveSink page(server, missions.empty() ? std::vector<std::string>{} : missions[0].fleet.get());
  dex::LiveLog log(std::cout);
  dex::TeeTrace tee;
  if (r.log) tee.add(&log);
  tee.add(&page);
  launch::LaunchResult result;
  int status = launch::launch(options, &tee, result, std::cout, std::cerr);
  status = report_launch(r, result, status);
  // Interrupted (Ctrl-C during the flight): the user wants out, not a page.
  if (result.run.error.find("interrupted") == std::string::npos) hold_after_launch(server);
  return status;
}

int report_launch(const RunCommandOptions& r, const launch::LaunchResult& result, int status) {
  if (!r.trace.empty()) {
    std::ofstream out(r.trace, std::ios::trunc);
    if (!out) {
      std::cerr << error_prefix() << "cannot write trace '" << r.trace << "'\n";
      return 1;
    }
    dex::JsonlTrace jsonl(out, result.fleet);
    report_trace_write_errors(jsonl, r.trace);
    jsonl.write_header(result.header);
    for (const auto& e : result.events) jsonl.record(e);
    if (!jsonl.write_error().empty()) status = 1;
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
      std::cerr << error_prefix() << "cannot make a temporary deployment folder\n";
      return 1;
    }
    dir = pattern;
  }
  Diagnostics diags;
  std::string hash = deploy::mission_hash(c);
  if (!deploy::write_deployment(c, dir, hash, diags)) {
    std::cerr << diags.format();
    return 1;
  }
  if (!write_security(c, dir, hash, security)) return 1;
  std::cout << "deployment in " << dir << "\n";
  options.dir = dir;
  options.insecure = security.insecure;
  return cmd_launch(options, r);
}

}  // namespace eamos::cli
