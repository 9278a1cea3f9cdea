// `eamos verify --plot`: the worst path's picture with its violations marked.
#include <algorithm>

#include "trace/plot.h"
#include "verify/flight.h"

namespace eamos::verify {

namespace {

/// "path 3 of 10 (2 violations): `Drone1.Sensor1() >= 100` (Drone1) false, forced; Drone1 10 % slower"
std::string caption(const VerifyReport& report) {
  const FlownPath& p = report.worst;
  std::string out = "Path " + std::to_string(p.number) + " of " + std::to_string(report.paths) + " flown, " +
                    count_of(p.violations, "violation");
  out += p.number == 1 && p.violations == 0 ? " (no path broke a rule)" : " (the path with the most)";
  std::string how;
  for (const Decision& d : p.decisions)
    how += (how.empty() ? "" : "; ") + d.text + " (" + d.drone + ") " + (d.value ? "true" : "false") +
           (d.forced ? ", forced" : "");
  if (!p.timing.empty()) how += (how.empty() ? "" : "; ") + p.timing;
  return out + (how.empty() ? ": every condition as the simulator read it, nominal timing" : ": " + how);
}

}  // namespace

namespace {

/// The worst path's flight, flown again: deterministic, so the same flight verify() checked.
Flight fly_worst(const Setup& setup, const VerifyReport& report) {
  Assignment forced(report.worst.forced.begin(), report.worst.forced.end());
  std::vector<double> factors = report.worst.factors;
  if (factors.size() != setup.missions.size()) factors.assign(setup.missions.size(), 1.0);
  return fly(setup, forced, factors, true);
}

/// Each violation of `f` at the position of the first drone it names (its last published one).
std::vector<PlacedViolation> place_violations(const Setup& setup, const Flight& f) {
  std::vector<PlacedViolation> out;
  for (const Violation& v : check_flight(setup, f)) {
    PlacedViolation p{v};
    for (const dex::DroneSummary& d : f.result.drones) {
      if (v.drones.empty() || d.name != v.drones.front()) continue;
      for (const dex::Sample& s : d.track)
        if (s.t <= v.t) p.x = s.x, p.y = s.y, p.z = s.z;
    }
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace

std::string plot_worst_path(const graph::Compilation& c, const std::vector<dex::Mission>& missions,
                            const VerifyOptions& options, const VerifyReport& report) {
  Setup setup{c, missions, options};
  Flight f = fly_worst(setup, report);
  std::vector<trace::PlotMark> marks;
  for (const PlacedViolation& p : place_violations(setup, f))
    marks.push_back(trace::PlotMark{p.violation.t, p.x, p.y, p.violation.kind});
  return trace::plot_svg(f.result, f.events, marks, caption(report));
}

WorstFlight fly_worst_path(const graph::Compilation& c, const std::vector<dex::Mission>& missions,
                           const VerifyOptions& options, const VerifyReport& report) {
  Setup setup{c, missions, options};
  Flight f = fly_worst(setup, report);
  WorstFlight out;
  out.violations = place_violations(setup, f);
  std::stable_sort(out.violations.begin(), out.violations.end(),
                   [](const PlacedViolation& a, const PlacedViolation& b) { return a.violation.t < b.violation.t; });
  out.events = std::move(f.events);
  out.drones = std::move(f.result.drones);
  return out;
}

}  // namespace eamos::verify
