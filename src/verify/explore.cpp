// verify(): which paths to fly. The first flight takes every condition as the simulated
// sensors decide it; each flight then names the free conditions it met (those on a sensor
// the fleet gives a range that allows both outcomes), and for each one not yet forced a new
// path keeps the outcomes before it and flips it: a depth-first enumeration of the outcome
// tree, flown breadth first so a small --paths still covers the early decisions.
#include <algorithm>
#include <deque>
#include <set>

#include "verify/flight.h"

namespace eamos::verify {

namespace {

/// Per-drone duration factors to fly each path with: nominal, then (with --jitter) every
/// drone 10 % slower, 10 % faster, and alternating drones slower and faster both ways, which
/// is where races between drones show.
std::vector<std::vector<double>> timings(int drones, bool jitter) {
  std::vector<std::vector<double>> out = {std::vector<double>(drones, 1.0)};
  if (!jitter) return out;
  out.push_back(std::vector<double>(drones, 1.1));
  out.push_back(std::vector<double>(drones, 0.9));
  if (drones > 1) {
    std::vector<double> a(drones), b(drones);
    for (int d = 0; d < drones; ++d) {
      a[d] = d % 2 ? 0.9 : 1.1;
      b[d] = d % 2 ? 1.1 : 0.9;
    }
    out.push_back(a);
    out.push_back(b);
  }
  return out;
}

std::string timing_text(const Setup& s, const std::vector<double>& factors) {
  std::string slower, faster;
  for (std::size_t d = 0; d < factors.size(); ++d) {
    std::string& list = factors[d] > 1 ? slower : factors[d] < 1 ? faster : slower;
    if (factors[d] == 1.0) continue;
    list += (list.empty() ? "" : ", ") + s.missions[d].settings.name;
  }
  std::string out;
  if (!slower.empty()) out += slower + " 10 % slower";
  if (!faster.empty()) out += (out.empty() ? "" : ", ") + faster + " 10 % faster";
  return out;
}

std::string identity(const Violation& v) {
  std::string key = v.kind + "|" + std::to_string(v.at.line) + ":" + std::to_string(v.at.col);
  std::vector<std::string> drones = v.drones;
  std::sort(drones.begin(), drones.end());
  for (const std::string& d : drones) key += "|" + d;
  if (v.at.line == 0) key += "|" + v.at.message;
  return key;
}

/// The paths to fly after `f` (which was flown with `forced`).
void children(const Flight& f, const Assignment& forced, std::deque<Assignment>& work, std::set<Assignment>& seen) {
  Assignment prefix = forced;
  for (std::size_t i = 0; i < f.decisions.size(); ++i) {
    const auto& key = f.decision_keys[i];
    bool value = f.decisions[i].value;
    if (!forced.count(key)) {
      Assignment child = prefix;
      child[key] = !value;
      if (seen.insert(child).second) work.push_back(child);
    }
    prefix[key] = value;
  }
}

FlownPath flown_path(const Setup& setup, const Assignment& forced, const Flight& f, int number, int violations) {
  FlownPath p;
  p.forced.assign(forced.begin(), forced.end());
  p.factors = f.factors;
  p.decisions = f.decisions;
  p.timing = timing_text(setup, f.factors);
  p.number = number;
  p.violations = violations;
  return p;
}

}  // namespace

VerifyReport verify(const graph::Compilation& c, const std::vector<dex::Mission>& missions,
                    const VerifyOptions& options) {
  VerifyReport report;
  if (missions.empty()) {
    report.error = "the mission has no drones";
    return report;
  }
  Setup setup{c, missions, options};
  std::vector<std::vector<double>> variants = timings(static_cast<int>(missions.size()), options.jitter);
  std::deque<Assignment> work{Assignment{}};
  std::set<Assignment> seen{Assignment{}};
  std::set<std::pair<int, int>> free;
  std::map<std::string, std::size_t> index;
  bool stopped = false;
  while (!work.empty() && !stopped) {
    Assignment forced = work.front();
    work.pop_front();
    for (const std::vector<double>& factors : variants) {
      if (report.paths >= options.max_paths) {
        stopped = true;
        break;
      }
      Flight f = fly(setup, forced, factors);
      ++report.paths;
      free.insert(f.decision_keys.begin(), f.decision_keys.end());
      std::vector<Violation> found = check_flight(setup, f);
      if (report.paths == 1 || static_cast<int>(found.size()) > report.worst.violations)
        report.worst = flown_path(setup, forced, f, report.paths, static_cast<int>(found.size()));
      for (Violation& v : found) {
        auto [it, added] = index.emplace(identity(v), report.violations.size());
        if (!added) {
          ++report.violations[it->second].paths_seen;
          continue;
        }
        v.timing = timing_text(setup, factors);
        report.violations.push_back(std::move(v));
      }
      children(f, forced, work, seen);
    }
  }
  report.complete = !stopped && work.empty();
  report.free_conditions = static_cast<int>(free.size());
  std::stable_sort(report.violations.begin(), report.violations.end(), [](const Violation& a, const Violation& b) {
    if (a.at.line != b.at.line) return a.at.line < b.at.line;
    if (a.at.col != b.at.col) return a.at.col < b.at.col;
    return a.t < b.t;
  });
  return report;
}

}  // namespace eamos::verify
