// verify(): which paths to fly. The first flight takes every condition as the simulated
// sensors decide it; each flight then names the free conditions it met (those on a sensor
// the fleet gives a range that allows both outcomes), and for each one not yet forced a new
// path keeps the outcomes before it and flips it: a depth-first enumeration of the outcome
// tree, flown breadth first so a small --paths still covers the early decisions.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <deque>
#include <set>
#include <system_error>
#include <thread>

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

/// The timings to fly one combination of outcomes with, in the order they were met.
struct Timings {
  std::vector<std::vector<double>> list;
  std::set<std::vector<double>> known;  ///< the same, to look up
  /// (drone, factor) of the timings that move one drone: a flight of the 100-drone squads
  /// names a thousand conditions, each with the drones it read, and building and looking up
  /// a whole timing for each was serial work between the flights.
  std::set<std::pair<int, double>> one_drone;
  void add(const std::vector<double>& v) {
    if (known.insert(v).second) list.push_back(v);
  }
  void add_one_drone(int drone, double factor, std::size_t drones) {
    if (!one_drone.emplace(drone, factor).second) return;
    std::vector<double> v(drones, 1.0);
    v[drone] = factor;
    add(v);
  }
};

/// Timings that move one drone against the rest: each drone a timing-dependent condition
/// read while it moved, 25 % slower and 25 % faster (20 % shorter), the others nominal.
void timing_variants(const std::map<std::pair<int, int>, std::pair<bool, std::vector<int>>>& timing_conditions,
                     std::size_t drones, Timings& variants) {
  for (const auto& [key, seen] : timing_conditions)
    for (int d : seen.second)
      for (double factor : {1.25, 0.8}) variants.add_one_drone(d, factor, drones);
}

std::string identity(const Violation& v) {
  std::string key = v.kind + "|" + std::to_string(v.at.line) + ":" + std::to_string(v.at.col);
  std::vector<std::string> drones = v.drones;
  std::sort(drones.begin(), drones.end());
  for (const std::string& d : drones) key += "|" + d;
  if (v.at.line == 0) key += "|" + v.at.message;
  return key;
}

/// What exploring needs of a flight once it is checked. The flight itself (its tracks) is
/// dropped there, so flights flown side by side hold only what they found.
struct Checked {
  std::vector<Violation> found;
  std::vector<Decision> decisions;
  std::vector<std::pair<int, int>> decision_keys;
  std::map<std::pair<int, int>, std::pair<bool, std::vector<int>>> timing_conditions;
  std::vector<double> factors;
};

Checked fly_and_check(const Setup& setup, const Assignment& forced, const std::vector<double>& factors) {
  Flight f = fly(setup, forced, factors);
  Checked c;
  c.found = check_flight(setup, f);
  c.decisions = std::move(f.decisions);
  c.decision_keys = std::move(f.decision_keys);
  c.timing_conditions = std::move(f.timing_conditions);
  c.factors = std::move(f.factors);
  return c;
}

/// Flies `forced` with each timing of `batch` on up to `jobs` threads: every flight has its own
/// event loop, simulators and engines, and reads only the shared mission. The results come
/// back in batch order, so what is reported does not depend on which thread finished first.
std::vector<Checked> fly_all(const Setup& setup, const Assignment& forced,
                             const std::vector<std::vector<double>>& batch, int jobs) {
  std::vector<Checked> out(batch.size());
  std::vector<std::exception_ptr> errors(batch.size());
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i; (i = next++) < batch.size();) {
      try {
        out[i] = fly_and_check(setup, forced, batch[i]);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  std::size_t threads = std::min<std::size_t>(batch.size(), static_cast<std::size_t>(std::max(jobs, 1)));
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t) {
    try {
      pool.emplace_back(worker);
    } catch (const std::system_error&) {
      break;  // no more threads to be had: the ones running (and this one) take the rest
    }
  }
  worker();
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
  return out;
}

int jobs_for(const VerifyOptions& options) {
  if (options.jobs > 0) return options.jobs;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

/// The paths to fly after `f` (which was flown with `forced`).
void children(const Checked& f, const Assignment& forced, std::deque<Assignment>& work, std::set<Assignment>& seen) {
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

FlownPath flown_path(const Setup& setup, const Assignment& forced, const Checked& f, int number, int violations) {
  FlownPath p;
  p.forced.assign(forced.begin(), forced.end());
  p.factors = f.factors;
  p.decisions = f.decisions;
  p.timing = timing_text(setup, f.factors);
  p.number = number;
  p.violations = violations;
  return p;
}

/// What verify() has learnt so far, flight after flight in the order they were flown.
struct Exploration {
  VerifyReport report;
  std::deque<Assignment> work{Assignment{}};
  std::set<Assignment> seen{Assignment{}};
  std::set<std::pair<int, int>> free;
  std::map<std::string, std::size_t> index;
  std::map<std::pair<int, int>, std::set<bool>> timing_outcomes;  // timing-dependent condition → seen
};

/// Takes in one flight of `forced`: its violations, the timings and paths it opens.
void take_in(const Setup& setup, const Assignment& forced, Checked& f, Timings& timings_here,
             Exploration& x) {
  VerifyReport& report = x.report;
  ++report.paths;
  x.free.insert(f.decision_keys.begin(), f.decision_keys.end());
  for (const auto& [key, seen] : f.timing_conditions) x.timing_outcomes[key].insert(seen.first);
  timing_variants(f.timing_conditions, f.factors.size(), timings_here);
  if (report.paths == 1 || static_cast<int>(f.found.size()) > report.worst.violations)
    report.worst = flown_path(setup, forced, f, report.paths, static_cast<int>(f.found.size()));
  for (Violation& v : f.found) {
    auto [it, added] = x.index.emplace(identity(v), report.violations.size());
    if (!added) {
      ++report.violations[it->second].paths_seen;
      continue;
    }
    v.timing = timing_text(setup, f.factors);
    report.violations.push_back(std::move(v));
  }
  children(f, forced, x.work, x.seen);
}

}  // namespace

VerifyReport verify(const graph::Compilation& c, const std::vector<dex::Mission>& missions,
                    const VerifyOptions& options) {
  if (missions.empty()) {
    VerifyReport none;
    none.error = "the mission has no drones";
    return none;
  }
  Setup setup{c, missions, options};
  std::vector<std::vector<double>> variants = timings(static_cast<int>(missions.size()), options.jitter);
  Exploration x;
  VerifyReport& report = x.report;
  int jobs = jobs_for(options);
  bool stopped = false;
  while (!x.work.empty() && !stopped) {
    Assignment forced = x.work.front();
    x.work.pop_front();
    Timings timings_here;  // grows with what the flights meet
    for (const std::vector<double>& v : variants) timings_here.add(v);
    // The timings known so far are flown side by side, then taken in in order: the same
    // paths, found in the same order, as flying them one after the other.
    for (std::size_t v = 0; v < timings_here.list.size();) {
      if (report.paths >= options.max_paths) {
        stopped = true;
        break;
      }
      std::size_t n =
          std::min(timings_here.list.size() - v, static_cast<std::size_t>(options.max_paths - report.paths));
      std::vector<std::vector<double>> batch(timings_here.list.begin() + v, timings_here.list.begin() + v + n);
      v += n;
      for (Checked& f : fly_all(setup, forced, batch, jobs)) take_in(setup, forced, f, timings_here, x);
    }
  }
  report.complete = !stopped && x.work.empty();
  report.free_conditions = static_cast<int>(x.free.size());
  for (const auto& [key, outcomes] : x.timing_outcomes) {
    if (x.free.count(key)) continue;
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
