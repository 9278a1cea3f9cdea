// The rules each flight is checked against (docs/verify.md). Every check reads the flight
// after it ended: the tracks (one sample per published change), the action runs and the
// trace; none of them changes what was flown.
#include <algorithm>
#include <cmath>

#include "mid/requests.h"
#include "verify/flight.h"
#include "verify/sweep.h"

namespace eamos::verify {

namespace {

const std::string& name_of(const Setup& s, int d) { return s.missions[d].settings.name; }

Located at_action(const ActionRun& a, std::string message) { return {a.node->line, a.node->col, std::move(message)}; }

/// The action to blame for something that happened to `drone` at `t`: the one running
/// then, else the last one it started before.
const ActionRun* responsible(const Flight& f, int drone, double t) {
  if (const ActionRun* a = running_at(f, drone, t)) return a;
  if (drone < 0 || static_cast<std::size_t>(drone) >= f.actions_of.size()) return nullptr;
  const ActionRun* last = nullptr;
  for (std::size_t i : f.actions_of[drone]) {
    if (f.actions[i].start > t) break;  // in start order
    last = &f.actions[i];
  }
  return last;
}

Violation make(const std::string& kind, double t, std::vector<std::string> drones, Located at) {
  Violation v;
  v.kind = kind;
  v.t = t;
  v.drones = std::move(drones);
  v.at = std::move(at);
  return v;
}

/// The sample of `track` in force at `t` (the last one at or before it).
const dex::Sample* sample_at(const std::vector<dex::Sample>& track, double t) {
  auto it = std::upper_bound(track.begin(), track.end(), t, [](double v, const dex::Sample& s) { return v < s.t; });
  return it == track.begin() ? nullptr : &*(it - 1);
}

bool rest_of_flight(const Flight& f, double t) { return f.abandoned_at >= 0 && t >= f.abandoned_at; }

// --- separation ----------------------------------------------------------------------------

/// The violation for drones a and b (a < b) coming too near at t: blamed on the action that
/// started last (the other drone was already doing its part), the lower-numbered on a tie.
Violation separation_violation(const Setup& s, const Flight& f, const Approach& near) {
  const fleet::Separation& sep = s.c.fleet.safety.min_separation;
  int a = near.a, b = near.b;
  const dex::Sample* pa = near.pa;
  const dex::Sample* pb = near.pb;
  double t = near.t;
  const ActionRun* ra = responsible(f, a, t);
  const ActionRun* rb = responsible(f, b, t);
  if (ra && rb && rb->start > ra->start) {
    std::swap(ra, rb);
    std::swap(a, b);
    std::swap(pa, pb);
  }
  std::string what = name_of(s, a) + " and " + name_of(s, b) + " come within " +
                     num(std::round(near.horizontal * 100) / 100) + " m horizontally and " +
                     num(std::round(near.vertical * 100) / 100) + " m vertically at " + seconds(t) +
                     " (min_separation " + num(sep.horizontal_m) + " m horizontally or " + num(sep.vertical_m) +
                     " m vertically)";
  std::string fix = "; keep them apart in space or time (a different target or altitude, or a WaitUntil on the other drone)";
  Violation viol = make("separation", t, {name_of(s, a), name_of(s, b)},
                        ra ? at_action(*ra, what + " while " + name_of(s, a) + " runs " + ra->node->text + fix)
                           : Located{0, 0, what + fix});
  if (rb)
    viol.notes.push_back(
        at_action(*rb, name_of(s, b) + " is running " + rb->node->text + " then, at " + point(pb->x, pb->y, pb->z)));
  if (ra && rest_of_flight(f, t)) viol.notes.push_back({0, 0, "this happens during the failsafe"});
  return viol;
}

Timeline timeline_of(const Flight& f) {
  std::vector<const std::vector<dex::Sample>*> tracks;
  for (const dex::DroneSummary& d : f.result.drones) tracks.push_back(&d.track);
  return timeline(std::move(tracks));
}

void check_separation(const Setup& s, const Flight& f, const Timeline& flight, std::vector<Violation>& out) {
  for (const Approach& near : approaches(flight, s.c.fleet.safety.min_separation))
    out.push_back(separation_violation(s, f, near));
}

// --- geofence ------------------------------------------------------------------------------

bool takes_off_or_lands(const ActionRun* a) {
  return a && (a->node->name == "Takeoff" || a->node->name == "Land" || a->node->name == "ReturnHome");
}

/// Is `p` inside the fence for the parts that apply to a drone doing `a`? The floor does
/// not apply while taking off or landing, nor on the ground.
bool inside(const fleet::Geofence& g, double x, double y, double z, bool airborne, const ActionRun* a) {
  if (!g.contains_xy(x, y)) return false;
  if (g.max_altitude_m && z > *g.max_altitude_m + 1e-6) return false;
  if (g.min_altitude_m && airborne && !takes_off_or_lands(a) && z < *g.min_altitude_m - 1e-6) return false;
  return true;
}

void check_targets(const Setup& s, const Flight& f, int d, const fleet::Geofence& g, std::vector<Violation>& out,
                   std::set<const ActionRun*>& reported) {
  for (const ActionRun& a : f.actions) {
    if (a.drone != d || !a.motion) continue;
    fleet::Vec3 here{a.state.x, a.state.y, a.state.z};
    std::optional<fleet::Vec3> goal = mid::goal_position(a.request, here, s.missions[d].settings.home);
    if (!goal || inside(g, goal->x, goal->y, goal->z, true, &a)) continue;
    out.push_back(make("geofence", a.start, {name_of(s, d)},
                       at_action(a, name_of(s, d) + "'s target " + point(goal->x, goal->y, goal->z) +
                                        " lies outside its geofence (at " + seconds(a.start) +
                                        "); move the target inside, or widen `geofence:` in the fleet file")));
    reported.insert(&a);
  }
}

void check_geofence(const Setup& s, const Flight& f, std::vector<Violation>& out) {
  for (std::size_t d = 0; d < f.result.drones.size(); ++d) {
    const fleet::Geofence* g = s.c.fleet.geofence_for(name_of(s, static_cast<int>(d)));
    if (!g) continue;
    std::set<const ActionRun*> reported;
    check_targets(s, f, static_cast<int>(d), *g, out, reported);
    bool outside = false;
    for (const dex::Sample& p : f.result.drones[d].track) {
      const ActionRun* a = responsible(f, static_cast<int>(d), p.t);
      bool now = !inside(*g, p.x, p.y, p.z, !p.landed, a);
      if (now && !outside && !reported.count(a)) {
        std::string what = name_of(s, static_cast<int>(d)) + " leaves its geofence at " + seconds(p.t) + ", at " +
                           point(p.x, p.y, p.z);
        out.push_back(make("geofence", p.t, {name_of(s, static_cast<int>(d))},
                           a ? at_action(*a, what + " while running " + a->node->text +
                                                 "; keep its path inside, or widen `geofence:` in the fleet file")
                             : Located{0, 0, what}));
        if (a) reported.insert(a);
      }
      outside = now;
    }
  }
}

// --- battery -------------------------------------------------------------------------------

void check_battery(const Setup& s, const Flight& f, std::vector<Violation>& out) {
  double reserve = s.c.fleet.safety.battery_reserve_percent;
  for (std::size_t d = 0; d < f.result.drones.size(); ++d) {
    const auto& track = f.result.drones[d].track;
    int drone = static_cast<int>(d);
    for (std::size_t i = 0; i < track.size(); ++i) {
      const dex::Sample& b = track[i];
      if (b.landed || !(b.battery < reserve)) continue;
      // The charge drains at a constant rate in the air: the crossing lies between the samples.
      double t = b.t;
      if (i > 0 && !track[i - 1].landed && track[i - 1].battery >= reserve && track[i - 1].battery > b.battery) {
        const dex::Sample& a = track[i - 1];
        t = a.t + (a.battery - reserve) / (a.battery - b.battery) * (b.t - a.t);
      }
      double landing = f.result.drones[d].state.battery;
      const ActionRun* r = responsible(f, drone, t);
      std::string what = name_of(s, drone) + " is in the air with less than the battery reserve of " + num(reserve) +
                         " % from " + seconds(t);
      what += landing <= 0 ? " and runs out" : " and lands with " + num(std::round(landing * 10) / 10) + " %";
      out.push_back(make("battery", t, {name_of(s, drone)},
                         r ? at_action(*r, what + ", during " + r->node->text +
                                               "; shorten the flight, start with more charge or land earlier")
                           : Located{0, 0, what}));
      break;
    }
  }
}

// --- speed and climb -----------------------------------------------------------------------

double rate_between(const std::string& kind, const dex::Sample& a, const dex::Sample& b) {
  double dt = b.t - a.t;
  return kind == "speed" ? std::hypot(b.x - a.x, b.y - a.y) / dt : kind == "climb" ? (b.z - a.z) / dt : (a.z - b.z) / dt;
}

void check_rate(const Setup& s, const Flight& f, int d, const std::string& kind, double limit,
                std::vector<Violation>& out) {
  const auto& track = f.result.drones[d].track;
  // A timing-perturbed flight flies 1/f as fast on purpose: judge it at nominal speed.
  double factor = f.factors[d];
  double peak = 0.0, first = -1.0;
  for (std::size_t i = 1; i < track.size(); ++i) {
    if (track[i].t - track[i - 1].t <= 1e-9 || track[i - 1].landed) continue;
    double rate = rate_between(kind, track[i - 1], track[i]) * factor;
    if (rate <= limit * 1.01 + 1e-6) continue;
    if (first < 0) first = track[i].t;
    peak = std::max(peak, rate);
  }
  if (first < 0) return;  // once per drone and kind: every later step would say the same
  const ActionRun* r = responsible(f, d, first);
  std::string key = kind == "speed" ? "max_speed" : kind == "climb" ? "max_climb" : "max_descent";
  std::string what = name_of(s, d) + (kind == "speed" ? " flies at up to " : kind == "climb" ? " climbs at up to " : " descends at up to ") +
                     num(std::round(peak * 100) / 100) + " m/s, above the fleet's " + key + " of " + num(limit) +
                     " m/s, from " + seconds(first);
  out.push_back(make(kind, first, {name_of(s, d)},
                     r ? at_action(*r, what + " during " + r->node->text + "; set `limits: {" + key + ": " + num(limit) +
                                           "}` for " + name_of(s, d) + " in the fleet file so its autopilot keeps to it")
                       : Located{0, 0, what}));
}

void check_rates(const Setup& s, const Flight& f, std::vector<Violation>& out) {
  const fleet::Safety& safety = s.c.fleet.safety;
  for (std::size_t d = 0; d < f.result.drones.size(); ++d) {
    int drone = static_cast<int>(d);
    if (safety.max_speed_mps) check_rate(s, f, drone, "speed", *safety.max_speed_mps, out);
    if (safety.max_climb_mps) check_rate(s, f, drone, "climb", *safety.max_climb_mps, out);
    if (safety.max_descent_mps) check_rate(s, f, drone, "descent", *safety.max_descent_mps, out);
  }
}

// --- take-off and landing spots -----------------------------------------------------------

Violation spot_violation(const Setup& s, const Flight& f, const ActionRun& a, double t, int other) {
  bool takeoff = a.node->name == "Takeoff";
  const dex::Sample* here = sample_at(f.result.drones[a.drone].track, t);
  const std::string& me = name_of(s, a.drone);
  std::string what = takeoff ? me + " takes off at " + seconds(t) + " from " + point(here->x, here->y, here->z) +
                                   ", where " + name_of(s, other) + " stands"
                             : me + " lands at " + seconds(t) + " on " + point(here->x, here->y, here->z) +
                                   ", where " + name_of(s, other) + " stands";
  return make("occupied_home", t, {me, name_of(s, other)},
              at_action(a, what + " (closer than " + num(s.c.fleet.safety.min_separation.horizontal_m) + " m); " +
                               (takeoff ? "give the drones homes at least that far apart"
                                        : "land elsewhere (FlyTo a free spot first) or wait until " +
                                              name_of(s, other) + " has left")));
}

void check_spots(const Setup& s, const Flight& f, const Timeline& flight, std::vector<Violation>& out) {
  std::vector<const ActionRun*> runs;
  std::vector<SpotQuery> queries;
  for (const ActionRun& a : f.actions) {
    bool takeoff = a.node->name == "Takeoff";
    bool landing = (a.node->name == "Land" || a.node->name == "ReturnHome") && a.outcome == "succeeded";
    if (!takeoff && !landing) continue;
    double t = takeoff ? a.start : a.end;
    const dex::Sample* here = sample_at(f.result.drones[a.drone].track, t);
    if (!here) continue;
    runs.push_back(&a);
    queries.push_back({a.drone, t, here->x, here->y});
  }
  double radius = s.c.fleet.safety.min_separation.horizontal_m;
  std::vector<int> others = standing_near(flight, queries, radius);
  for (std::size_t i = 0; i < runs.size(); ++i)
    if (others[i] >= 0) out.push_back(spot_violation(s, f, *runs[i], queries[i].t, others[i]));
}

// --- the end of the mission ------------------------------------------------------------------

void check_end_state(const Setup& s, const Flight& f, std::vector<Violation>& out) {
  if (!f.result.completed) return;  // a failed mission ended in failsafes, reported as its failure
  for (std::size_t d = 0; d < f.result.drones.size(); ++d) {
    int drone = static_cast<int>(d);
    const mid::DroneState& st = f.result.drones[d].state;
    if (dex::down_and_disarmed(st)) continue;
    const ActionRun* last = responsible(f, drone, f.result.duration);
    bool airborne = !st.landed;
    std::string what = name_of(s, drone) + (airborne ? " is still in the air" : " is still armed") +
                       " when the mission ends at " + seconds(f.result.duration) +
                       (airborne ? ", at " + point(st.x, st.y, st.z) : "") + "; end its part with " +
                       (airborne ? "Land() and Disarm()" : "Disarm()");
    out.push_back(make(airborne ? "airborne_at_end" : "armed_at_end", f.result.duration, {name_of(s, drone)},
                       last ? at_action(*last, what + " (its last action)") : Located{0, 0, what}));
  }
}

// --- failures and waits that never end -----------------------------------------------------

void check_failure(const Setup& s, const Flight& f, std::vector<Violation>& out) {
  const auto& fail = f.result.failure;
  if (!fail) return;
  Located at{fail->line, 0, ""};
  for (const ActionRun& a : f.actions)
    if (a.node->line == fail->line && s.missions[a.drone].settings.name == fail->drone && a.outcome == "failed")
      at.col = a.node->col;
  if (at.col == 0)  // a loop that takes no time fails at its condition, not an action
    for (const auto& [key, seen] : f.conditions)
      if (seen.node->line == fail->line) at.col = seen.node->col;
  at.message = fail->drone + "." + fail->action + " fails at " + seconds(f.result.duration) + ": " + fail->reason +
               "; the mission would abort and every drone run its failsafe";
  out.push_back(make("action_failed", f.result.duration, {fail->drone}, at));
  out.back().failure = mid::failure_reason_name(fail->kind);
}

bool waits_for(const dex::Node& n, bool value) {
  switch (n.control) {
    case lang::ControlKind::WaitUntil:
    case lang::ControlKind::PauseUntil: return !value;
    case lang::ControlKind::WaitWhile:
    case lang::ControlKind::PauseWhile: return value;
    default: return false;
  }
}

std::string last_reads(const Setup& s, int drone, const ConditionSeen& c) {
  std::string out;
  for (const auto& [read, value] : c.reads)
    out += (out.empty() ? "" : ", ") + s.missions[drone].fleet[read->drone] + "." + read->property + " = " + num(value);
  return out;
}

void check_never_ends(const Setup& s, const Flight& f, std::vector<Violation>& out) {
  if (f.result.completed || f.result.failure) return;
  std::string limit = num(s.options.time_limit_s) + " s";
  bool any = false;
  for (const auto& [key, c] : f.conditions) {
    if (!waits_for(*c.node, c.value)) continue;
    // Still waiting when the time limit hit: evaluated last with the "wait" value.
    any = true;
    const std::string& drone = name_of(s, key.first);
    Violation v = make("never_ends", f.result.duration, {drone},
                       {c.node->line, c.node->col,
                        std::string(lang::control_name(c.node->control)) + " on `" + c.node->text +
                            "` never ends: still waiting at the " +
                            limit + " time limit; it last read " + last_reads(s, key.first, c) + " (at " + seconds(c.t) +
                            "); make sure something makes `" + c.node->text + "` come true, or raise --time-limit"});
    out.push_back(std::move(v));
  }
  if (any) return;
  for (const ActionRun& a : f.actions) {
    // Running when the time limit hit: never ended, or ended by the abandonment then.
    bool still = !std::isfinite(a.end) || (f.abandoned_at >= 0 && a.start < f.abandoned_at && a.end >= f.abandoned_at);
    if (!still) continue;
    any = true;
    const std::string& drone = name_of(s, a.drone);
    out.push_back(make("never_ends", f.result.duration, {drone},
                       at_action(a, a.node->text + " still runs at the " + limit +
                                        " time limit and nothing ends it; give it an end (Hover(seconds), a Do* "
                                        "that preempts it) or raise --time-limit")));
  }
  if (!any) out.push_back(make("never_ends", f.result.duration, {}, {0, 0, f.result.error}));
}

}  // namespace

std::vector<Violation> check_flight(const Setup& s, const Flight& f) {
  std::vector<Violation> out;
  if (!f.result.error.empty() && f.result.drones.empty()) {
    out.push_back(make("action_failed", 0, {}, {0, 0, f.result.error}));
    return out;
  }
  check_failure(s, f, out);
  check_never_ends(s, f, out);
  Timeline flight = timeline_of(f);
  check_separation(s, f, flight, out);
  check_geofence(s, f, out);
  check_battery(s, f, out);
  check_rates(s, f, out);
  check_spots(s, f, flight, out);
  check_end_state(s, f, out);
  for (Violation& v : out) v.path = f.decisions;
  return out;
}

}  // namespace eamos::verify
