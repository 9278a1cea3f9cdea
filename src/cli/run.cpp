// `eamos run`: compile, load every drone's mission file into a DEX, fly them together in
// the built-in simulator (in-process transport), report like a ground station would.
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/signal_watch.h"
#include "deploy/mission_file.h"
#include "dex/plot.h"
#include "dex/runner.h"
#include "dex/trace_writers.h"
#include "graph/pipeline.h"
#include "mavlink_adapter/adapter.h"
#include "sim/sim_adapter.h"

namespace eamos::cli {

namespace {

nlohmann::ordered_json summary_json(const dex::RunResult& r) {
  nlohmann::ordered_json j;
  j["status"] = r.completed ? "completed" : "failed";
  j["duration"] = r.duration;
  if (!r.error.empty()) j["error"] = r.error;
  if (r.failure) {
    j["failure"] = {{"drone", r.failure->drone}, {"action", r.failure->action},
                    {"line", r.failure->line}, {"reason", r.failure->reason}};
    if (r.failure->kind != mid::FailureReason::none) j["failure"]["kind"] = mid::failure_reason_name(r.failure->kind);
    if (!r.failure->detail.empty()) j["failure"]["detail"] = r.failure->detail;
  }
  nlohmann::ordered_json drones = nlohmann::ordered_json::object();
  for (const auto& d : r.drones)
    drones[d.name] = {{"x", d.state.x}, {"y", d.state.y}, {"z", d.state.z}, {"armed", d.state.armed},
                      {"landed", d.state.landed}, {"battery", d.state.battery},
                      {"pictures", d.state.pictures}};
  j["drones"] = drones;
  return j;
}

}  // namespace

int cmd_run(const CommonOptions& o, const RunCommandOptions& r) {
  graph::Compilation c;
  if (!compile_and_report(o, c)) return 1;
  std::vector<dex::Mission> missions;
  if (!load_compiled_missions(c, missions)) return 1;
  // From here on drones may fly: Ctrl-C or SIGTERM lands them instead of killing the process
  // under them. First, before an adapter starts a thread that would inherit the old mask.
  dex::RunInterrupt interrupt;
  SignalWatch signals([&interrupt](const char* name) {
    interrupt.request(std::string("interrupted (") + name + ")");
  });
  mid::AdapterRegistry adapters;
  sim::register_adapter(adapters);
  mavlink_adapter::register_adapter(adapters, {.real_time = r.realtime || r.speed > 0,
                                               .speed = r.speed > 0 ? r.speed : 1.0});

  dex::TeeTrace tee;
  dex::LiveLog live(std::cout);
  if (r.log) tee.add(&live);
  std::ofstream trace_file;
  std::unique_ptr<dex::JsonlTrace> jsonl;
  if (!r.trace.empty()) {
    trace_file.open(r.trace, std::ios::trunc);
    if (!trace_file) {
      std::cerr << "eamos: error: cannot write trace '" << r.trace << "'\n";
      return 1;
    }
    jsonl = std::make_unique<dex::JsonlTrace>(trace_file);
    tee.add(jsonl.get());
  }
  dex::MemoryTrace memory;  // the plot is drawn from the whole trace after the run
  if (!r.plot.empty()) tee.add(&memory);
  dex::RunOptions options;
  options.time_limit_s = r.time_limit;
  options.interrupt = &interrupt;
  if (r.realtime || r.speed > 0) {
    options.clock.mode = mid::ClockMode::real_time;
    options.clock.speed = r.speed > 0 ? r.speed : 1.0;
  }
  dex::RunResult result = dex::run_in_process(missions, adapters, &tee, options);
  if (!report_run(r, result, memory.events)) return 1;
  return result.completed ? 0 : 1;
}

bool report_run(const RunCommandOptions& r, const dex::RunResult& result, const std::vector<dex::TraceEvent>& events) {
  if (!r.summary.empty() && !write_output(r.summary, summary_json(result).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n")) return false;
  if (!r.plot.empty() && !write_output(r.plot, dex::plot_svg(result, events))) return false;
  if (result.completed)
    std::cout << "mission completed in " << result.duration << " s (mission time)\n";
  else
    std::cerr << "eamos: mission failed: " << result.error << "\n";
  return true;
}

}  // namespace eamos::cli
