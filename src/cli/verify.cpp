// `eamos verify`: compile, read back every drone's mission file as `eamos run` does, and
// let src/verify fly every explored path in the simulator and check it.
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

/// The worst path's trace as `eamos run --trace` writes it, each violation merged in at its
/// instant (before the first later event; the mission's end stays the last line).
bool write_verify_trace(const std::string& path, const graph::Compilation& c, const std::vector<dex::Mission>& missions,
                        const verify::VerifyOptions& options, const verify::VerifyReport& report) {
  std::ofstream out(path, std::ios::trunc);
  if (!out) {
    std::cerr << error_prefix() << "cannot write trace '" << path << "'\n";
    return false;
  }
  verify::WorstFlight w = verify::fly_worst_path(c, missions, options, report);
  dex::JsonlTrace jsonl(out, missions[0].fleet);
  report_trace_write_errors(jsonl, path);
  jsonl.write_header(deploy::trace_header(c, missions[0].hash, 0.0));
  std::size_t next = 0;
  for (const dex::TraceEvent& e : w.events) {
    while (next < w.violations.size() && (e.event == "mission" || w.violations[next].violation.t < e.t))
      out << violation_line(w.violations[next++]);
    jsonl.record(e);
  }
  return jsonl.write_error().empty() && out.flush();
}

}  // namespace

int cmd_verify(const CommonOptions& o, const VerifyCommandOptions& v) {
  graph::Compilation c;
  if (!compile_and_report(o, c)) return 1;
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
