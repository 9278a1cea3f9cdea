// `eamos verify`: compile, read back every drone's mission file as `eamos run` does, and
// let src/verify fly every explored path in the simulator and check it.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "cli/arguments.h"
#include "cli/commands.h"
#include "deploy/mission_file.h"
#include "deploy/synthesize.h"
#include "dex/trace_writers.h"
#include "verify/verify.h"

namespace eamos::cli {

namespace {

/// {"t":..,"event":"violation","drone":..,"kind":..,"line":..,"text":..,"drones":[..]}
std::string violation_line(const verify::PlacedViolation& p) {
  const verify::Violation& v = p.violation;
  nlohmann::ordered_json j;
  j["t"] = v.t;
  j["event"] = "violation";
  j["drone"] = v.drones.empty() ? std::string() : v.drones.front();
  j["kind"] = v.kind;
  j["line"] = v.at.line;
  j["col"] = v.at.col;
  j["text"] = v.at.message;
  if (v.drones.size() > 1) j["drones"] = std::vector<std::string>(v.drones.begin() + 1, v.drones.end());
  j["x"] = p.x;
  j["y"] = p.y;
  j["z"] = p.z;
  return j.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

// Telemetry as a run's trace has it (docs/trace.md: on the 5-per-second grid, a sample only
// when something in it changed): each drone's state from its track, which holds a sample per
// change, so its last sample up to a step is its state then. Without it the monitor would draw
// every drone at its home for the whole flight.
constexpr double kVerifyTelemetryHz = 5.0;

bool same_sample(const dex::Sample& a, const dex::Sample& b) {
  return a.x == b.x && a.y == b.y && a.z == b.z && a.armed == b.armed && a.landed == b.landed && a.battery == b.battery;
}

dex::TraceEvent telemetry_event(const std::string& drone, double t, const dex::Sample& s) {
  mid::DroneState state;
  state.t = t;
  state.x = s.x, state.y = s.y, state.z = s.z;
  state.armed = s.armed, state.landed = s.landed, state.battery = s.battery;
  dex::TraceEvent e;
  e.t = t;
  e.drone = drone;
  e.event = "telemetry";
  e.state = state;
  return e;
}

std::vector<dex::TraceEvent> telemetry_events(const verify::WorstFlight& w, double end) {
  std::vector<dex::TraceEvent> out;
  const auto steps = static_cast<long>(std::floor(end * kVerifyTelemetryHz + 1e-9));
  for (const dex::DroneSummary& d : w.drones) {
    std::size_t at = 0;
    const dex::Sample* last = nullptr;
    for (long k = 0; k <= steps && !d.track.empty(); ++k) {
      double t = k / kVerifyTelemetryHz;
      while (at + 1 < d.track.size() && d.track[at + 1].t <= t + 1e-9) ++at;
      if (last && same_sample(*last, d.track[at])) continue;
      last = &d.track[at];
      out.push_back(telemetry_event(d.name, t, *last));
    }
  }
  return out;
}

/// The header says what the trace is: the worst path of a verification, with its violations.
nlohmann::ordered_json verify_header(const graph::Compilation& c, const std::vector<dex::Mission>& missions,
                                     const verify::VerifyReport& report, std::size_t violations) {
  nlohmann::ordered_json h = deploy::trace_header(c, missions[0].hash, kVerifyTelemetryHz);
  h["run"] = "verify";
  h["path"] = report.worst.number;
  h["paths"] = report.paths;
  h["violations"] = violations;
  return h;
}

/// The worst path's trace as `eamos run --trace` writes it, with telemetry and each violation
/// merged in at its instant (before the first later event; the mission's end stays the last line).
bool write_verify_trace(const std::string& path, const graph::Compilation& c, const std::vector<dex::Mission>& missions,
                        const verify::VerifyOptions& options, const verify::VerifyReport& report) {
  std::ofstream out(path, std::ios::trunc);
  if (!out) {
    std::cerr << error_prefix() << "cannot write trace '" << path << "'\n";
    return false;
  }
  verify::WorstFlight w = verify::fly_worst_path(c, missions, options, report);
  std::vector<dex::TraceEvent> events, ends;
  for (dex::TraceEvent& e : w.events) (e.event == "mission" ? ends : events).push_back(std::move(e));
  double end = events.empty() ? 0.0 : events.back().t;
  for (const dex::TraceEvent& e : ends) end = std::max(end, e.t);
  std::vector<dex::TraceEvent> samples = telemetry_events(w, end);
  events.insert(events.end(), samples.begin(), samples.end());
  std::stable_sort(events.begin(), events.end(), [](const dex::TraceEvent& a, const dex::TraceEvent& b) { return a.t < b.t; });
  events.insert(events.end(), ends.begin(), ends.end());
  dex::JsonlTrace jsonl(out, missions[0].fleet);
  report_trace_write_errors(jsonl, path);
  jsonl.write_header(verify_header(c, missions, report, w.violations.size()));
  std::size_t next = 0;
  for (const dex::TraceEvent& e : events) {
    while (next < w.violations.size() && (e.event == "mission" || w.violations[next].violation.t < e.t))
      out << violation_line(w.violations[next++]);
    jsonl.record(e);
  }
  while (next < w.violations.size()) out << violation_line(w.violations[next++]);
  return jsonl.write_error().empty() && out.flush();
}

}  // namespace

int cmd_verify(const CommonOptions& o, const VerifyCommandOptions& v) {
  graph::Compilation c;
  if (!compile_and_report(o, c, graph::Keep::deployment_graphs)) return 1;
  std::vector<dex::Mission> missions;
  if (!load_compiled_missions(c, missions)) return 1;
  verify::VerifyOptions options;
  options.max_paths = v.paths;
  options.jitter = v.jitter;
  options.time_limit_s = v.time_limit;
  verify::VerifyReport report = verify::verify(c, missions, options);
  if (!v.plot.empty() && !write_output(v.plot, verify::plot_worst_path(c, missions, options, report))) return 1;
  if (!v.trace.empty() && report.error.empty() && !write_verify_trace(v.trace, c, missions, options, report)) return 1;
  std::cerr.flush();
  std::string text = v.json ? verify::json_report(c, report) : verify::format_report(c, report);
  // The summary line names its mission: a script verifying several says which is which.
  if (!v.json && report.error.empty()) {
    std::size_t last = text.rfind('\n', text.size() >= 2 ? text.size() - 2 : 0);
    text.insert(last == std::string::npos ? 0 : last + 1, o.mission + ": ");
  }
  std::cout << text;
  std::cout.flush();
  return report.error.empty() && report.violations.empty() ? 0 : 1;
}

}  // namespace eamos::cli
