// `eamos verify --plot`: the first path's picture with its violations marked.
#include <algorithm>

#include "dex/plot.h"
#include "verify/flight.h"

namespace eamos::verify {

std::string plot_first_path(const graph::Compilation& c, const std::vector<dex::Mission>& missions,
                            const VerifyOptions& options) {
  Setup setup{c, missions, options};
  Flight f = fly(setup, {}, std::vector<double>(missions.size(), 1.0));
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
  return dex::plot_svg(f.result, f.events, marks);
}

}  // namespace eamos::verify
