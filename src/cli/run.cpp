// `eamos run`: compile, load every drone's mission file into a DEX, fly them together in
// the built-in simulator (in-process transport), report like a ground station would.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "cli/arguments.h"
#include "cli/commands.h"
#include "cli/progress.h"
#include "cli/signal_watch.h"
#include "deploy/mission_file.h"
#include "deploy/synthesize.h"
#include "diag/number.h"
#include "trace/plot.h"
#include "dex/runner.h"
#include "dex/trace_writers.h"
#include "graph/pipeline.h"
#include "mavlink_adapter/adapter.h"
#include "monitor/live_sink.h"
#include "monitor/server.h"
#include "sim/sim_adapter.h"

namespace eamos::cli {

namespace {

/// The triggers and cancels between drones: how many, how late (mission seconds), and each
/// one later than the warning bound.
nlohmann::ordered_json latency_json(const dex::MessageLatency& m) {
  // Microseconds, as in the trace.
  auto us = [](double s) { return std::round(s * 1e6) / 1e6; };
  nlohmann::ordered_json late = nlohmann::ordered_json::array();
  for (const dex::LateMessage& l : m.late)
    late.push_back({{"kind", l.kind}, {"from", l.from}, {"to", l.to}, {"node", l.node}, {"sent", us(l.sent)},
                    {"latency", us(l.latency)}});
  return {{"count", m.count}, {"latency_max", us(m.max_s)}, {"latency_p99", us(m.p99_s)}, {"warn_above", m.warn_s},
          {"late", late}};
}

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
  for (const auto& d : r.drones) {
    nlohmann::ordered_json state = {{"x", d.state.x}, {"y", d.state.y}, {"z", d.state.z}, {"armed", d.state.armed},
                                    {"landed", d.state.landed}, {"battery", d.state.battery},
                                    {"pictures", d.state.pictures}};
    // Not known is not "armed at 10 m": the last state seen is kept apart from the answer.
    if (d.final)
      drones[d.name] = state;
    else
      drones[d.name] = {{"state", "unknown"}, {"last_seen", state}};
  }
  j["drones"] = drones;
  if (r.latency) j["messages"] = latency_json(*r.latency);
  return j;
}

void print_latency(const dex::MessageLatency& m) {
  if (m.count == 0) return;
  char text[200];
  std::snprintf(text, sizeof text,
                "message latency: max %.3f s, p99 %.3f s over %zu triggers and cancels (mission time); %zu later "
                "than %g s\n",
                m.max_s, m.p99_s, m.count, m.late.size(), m.warn_s);
  (m.late.empty() ? std::cout : std::cerr) << text;
}

/// Nothing was started: no drone was created, nothing written.
int interrupted_before_start() {
  std::cerr << "eamos: no drone was started, nothing written\n";
  return 1;
}

/// Where a run's events go: the terminal (status lines or log lines), the trace file, the
/// plot's memory, the live monitor. Held in place: the tee points at the others.
struct RunSinks {
  dex::TeeTrace tee;
  dex::LiveLog live{std::cout};
  std::unique_ptr<ProgressDisplay> progress;
  std::ofstream trace_file;
  std::unique_ptr<dex::JsonlTrace> jsonl;
  std::unique_ptr<trace::PlotTrace> plot;  ///< the plot is drawn from the whole trace after the run
  std::unique_ptr<monitor::MonitorServer> server;
  std::unique_ptr<monitor::LiveSink> live_monitor;
};

/// Only a run with --monitor has a server at all: without it nothing of civetweb is touched.
bool open_monitor(const RunCommandOptions& r, const nlohmann::json& view, const dex::Mission& mission,
                  RunSinks& sinks) {
  if (r.monitor.empty()) return true;
  sinks.server = std::make_unique<monitor::MonitorServer>();
  if (!start_monitor(*sinks.server, r.monitor, view)) return false;
  sinks.live_monitor = std::make_unique<monitor::LiveSink>(*sinks.server, mission.fleet);
  std::cout << "eamos: monitor at " << sinks.server->url() << "\n" << std::flush;
  return true;
}

bool open_sinks(const RunCommandOptions& r, const graph::Compilation& c, const std::vector<dex::Mission>& missions,
                RunSinks& sinks) {
  // On a terminal, a status line per drone redrawn in place; through a pipe, the log lines.
  if (r.log && stdout_is_terminal()) sinks.progress = std::make_unique<ProgressDisplay>(std::cout, missions);
  if (sinks.progress) sinks.tee.add(sinks.progress.get());
  else if (r.log) sinks.tee.add(&sinks.live);
  sinks.live.set_flush_each_line(!run_log_in_blocks(r));
  if (!r.trace.empty()) {
    sinks.trace_file.open(r.trace, std::ios::trunc);
    if (!sinks.trace_file) {
      std::cerr << error_prefix() << "cannot write trace '" << r.trace << "'\n";
      return false;
    }
    sinks.jsonl = std::make_unique<dex::JsonlTrace>(sinks.trace_file, missions[0].fleet);
    // Said when it happens, not at the end: the flight goes on, without its record.
    report_trace_write_errors(*sinks.jsonl, r.trace);
    sinks.jsonl->write_header(deploy::trace_header(c, missions[0].hash, r.telemetry_hz));
    sinks.tee.add(sinks.jsonl.get());
  }
  if (!r.plot.empty()) {
    sinks.plot = std::make_unique<trace::PlotTrace>(missions[0].fleet.size());
    sinks.tee.add(sinks.plot.get());
  }
  if (sinks.live_monitor) sinks.tee.add(sinks.live_monitor.get());
  return true;
}

dex::RunOptions run_options(const RunCommandOptions& r, dex::RunInterrupt& interrupt, const RunSinks& sinks) {
  dex::RunOptions options;
  options.time_limit_s = r.time_limit;
  options.keep_tracks = !r.plot.empty();  // only the plot draws them
  options.interrupt = &interrupt;
  // Samples cost a copy of every drone's state per tick: only when a trace file or the
  // terminal's status lines (their clock) take them.
  options.telemetry_hz = sinks.jsonl || sinks.progress || sinks.live_monitor ? r.telemetry_hz : 0.0;
  if (r.realtime || r.speed > 0) {
    options.clock.mode = mid::ClockMode::real_time;
    options.clock.speed = r.speed > 0 ? r.speed : 1.0;
  }
  return options;
}

}  // namespace

int cmd_run(const CommonOptions& o, const RunCommandOptions& r) {
  // Ctrl-C or SIGTERM lands the drones instead of killing the process under them. Taken from
  // the very start, before any thread exists (an adapter's would inherit the old mask): a
  // signal while compiling or drawing the monitor's graphs (with --monitor, Graphviz runs
  // for seconds on a loaded machine) must not kill the process with the default action.
  dex::RunInterrupt interrupt;
  MonitorHold hold;
  SignalWatch signals([&interrupt, &hold](const char* name) {
    // Said before anything is done about it: the failsafes' log lines come after it.
    if (interrupt.over())
      std::fprintf(stderr, "eamos: interrupted (%s): the mission has ended; the monitor stops\n", name);
    else if (interrupt.running())
      std::fprintf(stderr,
                   "eamos: interrupted (%s): every drone runs its failsafe; interrupt again to exit at once\n", name);
    else
      std::fprintf(stderr, "eamos: interrupted (%s) before the mission started\n", name);
    interrupt.request(std::string("interrupted (") + name + ")");
    hold.signal();
  });
  graph::Compilation c;
  // Flying needs the MEG and the MDGs only; the live page also draws the AMT.
  if (!compile_and_report(o, c, r.monitor.empty() ? graph::Keep::deployment_graphs : graph::Keep::all_graphs))
    return 1;
  std::vector<dex::Mission> missions;
  if (!load_compiled_missions(c, missions)) return 1;
  nlohmann::json view;
  if (!r.monitor.empty()) view = live_view(c, o.mission, o.fleet);
  if (hold.was_interrupted()) return interrupted_before_start();
  RunSinks sinks;
  if (!open_monitor(r, view, missions[0], sinks)) return 1;
  // A signal from here on is the run's (RunInterrupt keeps it until the run starts).
  mid::AdapterRegistry adapters;
  sim::register_adapter(adapters);
  mavlink_adapter::register_adapter(adapters, {.real_time = r.realtime || r.speed > 0,
                                               .speed = r.speed > 0 ? r.speed : 1.0});
  if (!open_sinks(r, c, missions, sinks)) return 1;
  dex::RunResult result = dex::run_in_process(missions, adapters, &sinks.tee, run_options(r, interrupt, sinks));
  if (sinks.progress) sinks.progress->finish();
  if (!report_run(r, result, sinks.plot ? sinks.plot->events : std::vector<dex::TraceEvent>{})) return 1;
  // A completed mission whose trace was cut is not a run to take as recorded.
  bool trace_cut = sinks.jsonl && !sinks.jsonl->write_error().empty();
  if (trace_cut)
    std::cerr << "eamos: error: the trace '" << r.trace << "' is incomplete (" << sinks.jsonl->write_error() << ")\n";
  if (sinks.live_monitor && !hold.was_interrupted()) hold_monitor(*sinks.server, hold);
  return result.completed && !trace_cut ? 0 : 1;
}

void hold_monitor(monitor::MonitorServer& server, MonitorHold& hold) {
  server.finish();
  std::cout << "eamos: the mission has ended; the monitor shows it at " << server.url()
            << " until Ctrl-C\n" << std::flush;
  hold.wait_for_signal();
}

bool report_run(const RunCommandOptions& r, const dex::RunResult& result, const std::vector<dex::TraceEvent>& events) {
  if (!r.summary.empty() && !write_output(r.summary, summary_json(result).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n")) return false;
  if (!r.plot.empty() && !write_output(r.plot, trace::plot_svg(result, events))) return false;
  if (result.latency) print_latency(*result.latency);
  if (result.completed) {
    std::cout << "mission completed in " << result.duration << " s (mission time)\n" << std::flush;
  } else if (!result.error.empty()) {
    std::cerr << "eamos: mission failed: " << result.error << "\n";
  } else {  // a launch that stopped before the flight: its reason is already on standard error
    std::cerr << "eamos: mission failed (see the error above)\n";
  }
  std::string pace = r.speed > 0 ? "--speed " + diag::number_text(r.speed) : std::string("--realtime");
  for (const std::string& w : dex::run_warnings(result, pace)) std::cerr << "eamos: warning: " << w << "\n";
  return true;
}

}  // namespace eamos::cli
