// verify(): which paths to fly. The first flight takes every condition as the simulated
// sensors decide it; each flight then names the free conditions it met (those on a sensor
// the fleet gives a range that allows both outcomes), and for each one not yet forced a new
// path keeps the outcomes before it and flips it: a depth-first enumeration of the outcome
// tree, flown breadth first so a small --paths still covers the early decisions.
#include <algorithm>
#include <cmath>
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

/// "Drone1, Drone3 10 % slower, Drone2 25 % faster": drones grouped by how their timing moved.
std::string timing_text(const Setup& s, const std::vector<double>& factors) {
  std::vector<std::pair<std::string, std::string>> groups;  // "10 % slower" → drones
  for (std::size_t d = 0; d < factors.size(); ++d) {
    if (factors[d] == 1.0) continue;
    int percent = static_cast<int>(std::lround(std::abs(factors[d] > 1 ? factors[d] - 1 : 1 - factors[d]) * 100));
    std::string how = std::to_string(percent) + " % " + (factors[d] > 1 ? "slower" : "faster");
    auto it = std::find_if(groups.begin(), groups.end(), [&](const auto& g) { return g.first == how; });
    if (it == groups.end()) it = groups.insert(groups.end(), {how, ""});
    it->second += (it->second.empty() ? "" : ", ") + s.missions[d].settings.name;
  }
  std::stable_sort(groups.begin(), groups.end(), [](const auto& a, const auto& b) {
    return (a.first.find("slower") != std::string::npos) > (b.first.find("slower") != std::string::npos);
  });
  std::string out;
  for (const auto& [how, drones] : groups) out += (out.empty() ? "" : ", ") + drones + " " + how;
  return out;
}

/// Timings that move one drone against the rest: each drone a timing-dependent condition
/// read while it moved, 25 % slower and 25 % faster (20 % shorter), the others nominal.
void timing_variants(const Flight& f, std::vector<std::vector<double>>& variants) {
  for (const auto& [key, seen] : f.timing_conditions)
    for (int d : seen.second)
      for (double factor : {1.25, 0.8}) {
        std::vector<double> v(f.factors.size(), 1.0);
        v[d] = factor;
        if (std::find(variants.begin(), variants.end(), v) == variants.end()) variants.push_back(v);
      }
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
  std::map<std::pair<int, int>, std::set<bool>> timing_outcomes;  // timing-dependent condition → seen
  bool stopped = false;
  while (!work.empty() && !stopped) {
    Assignment forced = work.front();
    work.pop_front();
    std::vector<std::vector<double>> timings_here = variants;  // grows with what the flights meet
    for (std::size_t v = 0; v < timings_here.size(); ++v) {
      if (report.paths >= options.max_paths) {
        stopped = true;
        break;
      }
      const std::vector<double> factors = timings_here[v];
      Flight f = fly(setup, forced, factors);
      ++report.paths;
      free.insert(f.decision_keys.begin(), f.decision_keys.end());
      for (const auto& [key, seen] : f.timing_conditions) timing_outcomes[key].insert(seen.first);
      timing_variants(f, timings_here);
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
  for (const auto& [key, outcomes] : timing_outcomes) {
    if (free.count(key)) continue;
    ++report.timing_conditions;
    if (outcomes.size() == 2) ++report.timing_both_ways;
  }
  std::stable_sort(report.violations.begin(), report.violations.end(), [](const Violation& a, const Violation& b) {
    if (a.at.line != b.at.line) return a.at.line < b.at.line;
    if (a.at.col != b.at.col) return a.at.col < b.at.col;
    return a.t < b.t;
  });
  return report;
}

}  // namespace eamos::verify
