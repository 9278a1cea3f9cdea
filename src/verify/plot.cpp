// `eamos verify --plot`: the worst path's picture with its violations marked.
#include <algorithm>

#include "dex/plot.h"
#include "verify/flight.h"

namespace eamos::verify {

namespace {

/// "path 3 of 10 (2 violations): `Drone1.Sensor1() >= 100` (Drone1) false, forced; Drone1 10 % slower"
std::string caption(const VerifyReport& report) {
  const FlownPath& p = report.worst;
  std::string out = "Path " + std::to_string(p.number) + " of " + std::to_string(report.paths) + " flown, " +
                    std::to_string(p.violations) + " violation(s)";
  out += p.number == 1 && p.violations == 0 ? " (no path broke a rule)" : " (the path with the most)";
  std::string how;
  for (const Decision& d : p.decisions)
    how += (how.empty() ? "" : "; ") + d.text + " (" + d.drone + ") " + (d.value ? "true" : "false") +
           (d.forced ? ", forced" : "");
  if (!p.timing.empty()) how += (how.empty() ? "" : "; ") + p.timing;
  return out + (how.empty() ? ": every condition as the simulator read it, nominal timing" : ": " + how);
}

}  // namespace

std::string plot_worst_path(const graph::Compilation& c, const std::vector<dex::Mission>& missions,
                            const VerifyOptions& options, const VerifyReport& report) {
  Setup setup{c, missions, options};
  Assignment forced(report.worst.forced.begin(), report.worst.forced.end());
  std::vector<double> factors = report.worst.factors;
  if (factors.size() != missions.size()) factors.assign(missions.size(), 1.0);
  Flight f = fly(setup, forced, factors);  // deterministic: the same flight verify() checked
  std::vector<dex::PlotMark> marks;
  for (const Violation& v : check_flight(setup, f)) {
    dex::PlotMark m{v.t, 0.0, 0.0, v.kind};
    // Where the first drone named was at that moment (its last published position).
    for (const dex::DroneSummary& d : f.result.drones) {
      if (v.drones.empty() || d.name != v.drones.front()) continue;
      for (const dex::Sample& s : d.track)
        if (s.t <= v.t) m.x = s.x, m.y = s.y;
    }
    marks.push_back(m);
  }
  return dex::plot_svg(f.result, f.events, marks, caption(report));
}

}  // namespace eamos::verify
