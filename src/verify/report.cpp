// The verifier's report as people read it (GCC-style diagnostics with notes) and as tools
// read it (JSON).
#include <nlohmann/json.hpp>

#include "verify/flight.h"

namespace eamos::verify {

namespace {

/// One diagnostic as Diagnostics prints it (with its source line and caret); kept apart so
/// notes stay right under their error instead of being sorted by position.
std::string one(const graph::Compilation& c, Severity severity, const Located& at) {
  Diagnostics d;
  SourceLocation loc{at.line, at.col};
  const SourceFile* file = at.line > 0 ? c.source.get() : nullptr;
  if (severity == Severity::error) d.error(file, loc, at.message);
  else d.note(file, loc, at.message);
  return d.format();
}

std::string outcome_text(const Decision& d) {
  std::string how = d.forced ? "forced; the fleet's sensor range allows it" : "as the simulated sensor reads";
  return "on this path `" + d.text + "` (" + d.drone + ") is " + (d.value ? "true" : "false") + " (" + how + ")";
}

}  // namespace

std::string format_report(const graph::Compilation& c, const VerifyReport& r) {
  std::string out;
  if (!r.error.empty()) return "eamos: verify: " + r.error + "\n";
  for (const Violation& v : r.violations) {
    out += one(c, Severity::error, v.at);
    for (const Located& n : v.notes) out += one(c, Severity::note, n);
    bool on_every_path = v.paths_seen == r.paths;
    if (!v.path.empty() || !v.timing.empty() || !on_every_path) {
      std::string where = "found on " + std::to_string(v.paths_seen) + " of " + count_of(r.paths, "path") +
                          " flown" + (v.timing.empty() ? "" : ", first with " + v.timing);
      out += one(c, Severity::note, {0, 0, where});
      for (const Decision& d : v.path) out += one(c, Severity::note, {d.line, d.col, outcome_text(d)});
    }
  }
  out += count_of(r.violations.size(), "violation") + " on " + count_of(r.paths, "path") + " flown";
  out += r.complete ? "; exploration complete" : "; exploration incomplete (raise --paths to fly more)";
  out += " (" + count_of(r.free_conditions, "condition") + " explored both ways";
  if (r.timing_conditions > 0)
    out += "; " + std::to_string(r.timing_conditions) + " on other drones' timing, " +
           std::to_string(r.timing_both_ways) + " of them seen both ways";
  out += ")\n";
  return out;
}

std::string json_report(const graph::Compilation& c, const VerifyReport& r) {
  nlohmann::ordered_json j;
  j["file"] = c.source ? c.source->path : "";
  j["paths"] = r.paths;
  j["complete"] = r.complete;
  j["free_conditions"] = r.free_conditions;
  j["timing_conditions"] = r.timing_conditions;
  j["timing_both_ways"] = r.timing_both_ways;
  if (!r.error.empty()) j["error"] = r.error;
  j["violations"] = nlohmann::ordered_json::array();
  for (const Violation& v : r.violations) {
    nlohmann::ordered_json e;
    e["kind"] = v.kind;
    e["t"] = v.t;
    e["drones"] = v.drones;
    e["line"] = v.at.line;
    e["col"] = v.at.col;
    e["message"] = v.at.message;
    e["notes"] = nlohmann::ordered_json::array();
    for (const Located& n : v.notes) e["notes"].push_back({{"line", n.line}, {"col", n.col}, {"message", n.message}});
    e["path"] = nlohmann::ordered_json::array();
    for (const Decision& d : v.path)
      e["path"].push_back({{"drone", d.drone}, {"line", d.line}, {"col", d.col}, {"condition", d.text},
                           {"value", d.value}, {"forced", d.forced}});
    e["timing"] = v.timing;
    e["paths_seen"] = v.paths_seen;
    if (!v.failure.empty()) e["failure"] = v.failure;
    j["violations"].push_back(e);
  }
  return j.dump(2) + "\n";
}

}  // namespace eamos::verify
