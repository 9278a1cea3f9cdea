// One flight of the mission on virtual time, with an observer that records every action
// start and condition evaluation and decides the conditions the path forces.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <unordered_map>

#include "sim/sim_drone.h"
#include "verify/flight.h"

namespace eamos::verify {

std::string num(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", std::abs(v) < 5e-7 ? 0.0 : v);
  return text;
}
std::string seconds(double t) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f s", t);
  return text;
}
std::string point(double x, double y, double z) {
  auto r = [](double v) { return num(std::round(v * 100) / 100); };
  return "(" + r(x) + ", " + r(y) + ", " + r(z) + ")";
}

namespace {

void collect_reads(const dex::Expr& e, std::vector<const dex::Expr*>& out) {
  if (e.kind == dex::Expr::Kind::property) out.push_back(&e);
  for (const dex::Expr& a : e.args) collect_reads(a, out);
}
void collect_numbers(const dex::Expr& e, std::vector<double>& out) {
  if (e.kind == dex::Expr::Kind::number) out.push_back(e.number);
  for (const dex::Expr& a : e.args) collect_numbers(a, out);
}

/// A sensor read of a condition whose value the fleet lets range over [low, high].
struct RangedRead {
  int drone;
  std::string sensor;
  fleet::SensorRange range;
};

/// Values worth trying for a sensor over its range: both ends, every number the condition
/// compares with (and just either side of it), and a grid between. For the comparisons a
/// mission writes (a sensor against constants) this finds every outcome the range allows.
std::vector<double> candidates(const fleet::SensorRange& r, const std::vector<double>& numbers) {
  std::vector<double> v = {r.low, r.high};
  for (int i = 1; i < 16; ++i) v.push_back(r.low + (r.high - r.low) * i / 16.0);
  for (double n : numbers)
    for (double c : {n, n - 1e-6 * std::max(1.0, std::abs(n)), n + 1e-6 * std::max(1.0, std::abs(n))})
      if (c >= r.low && c <= r.high) v.push_back(c);
  return v;
}

/// What the observer keeps about one node of one drone's mission over a flight.
struct NodeWatch {
  std::vector<std::size_t> open;        ///< an action's runs still running (in Flight::actions), oldest first
  std::vector<const dex::Expr*> reads;  ///< a condition's property reads
  ConditionSeen seen;                   ///< a condition's last evaluation (seen.node set once evaluated)
  signed char free = -1;                ///< a condition explored both ways: 1 yes, 0 no, -1 not yet known
  bool started = false;                 ///< an action that ran at least once
  bool motion = false;                  ///< an action of the motion class
  bool reads_known = false;
  bool timing_noted = false;            ///< a condition already in Flight::timing_conditions
};

class Observer : public dex::RunObserver, public dex::TraceSink {
 public:
  Observer(const Setup& setup, const Assignment& forced, Flight& f, bool whole_trace)
      : setup_(setup), forced_(forced), f_(f), whole_trace_(whole_trace), watch_(setup.missions.size()) {
    const auto& names = setup_.missions[0].fleet;
    for (std::size_t d = names.size(); d-- > 0;) index_of_[names[d]] = static_cast<int>(d);  // the first of equal names
    for (std::size_t d = 0; d < watch_.size(); ++d) watch_[d].resize(setup_.missions[d].nodes.size());
    f_.actions_of.resize(setup_.missions.size());
  }

  // Every arrival delivered, on every flight: the runner's counted barriers (taken when no
  // sink keeps messages) flew Listing 2 differently when the missions' drone sets were equal
  // but not one table, and the worst path is flown again with its messages for the picture.
  bool takes_messages() const override { return true; }

  void action_started(double t, int drone, const dex::Node& node, const mid::ActionRequest& request,
                      const mid::DroneState& state) override {
    NodeWatch& w = watch(drone, node);
    if (!w.started) {  // the first run of this node: what it is
      const fleet::ActionSpec* spec = setup_.missions[drone].type.find_action(node.name);
      w.motion = spec && spec->action_class == fleet::ActionClass::motion;
      w.started = true;
    }
    ActionRun& a = f_.actions.emplace_back();
    a.drone = drone;
    a.node = &node;
    a.request = request;
    a.state = state;
    a.start = t;
    a.motion = w.motion;
    w.open.push_back(f_.actions.size() - 1);
    f_.actions_of[drone].push_back(f_.actions.size() - 1);
  }

  bool condition(double t, int drone, const dex::Node& node, bool computed, const dex::PropertyReader& read) override {
    NodeWatch& w = watch(drone, node);
    if (!w.reads_known) collect_reads(node.condition, w.reads);
    w.reads_known = true;
    ConditionSeen& seen = w.seen;
    seen.node = &node;
    seen.t = t;
    seen.reads.clear();
    for (const dex::Expr* r : w.reads) seen.reads.emplace_back(r, read(r->drone, r->property));
    bool value = decide(drone, node, w, computed, read);
    seen.value = value;
    note_timing(t, drone, node, w, value);
    return value;
  }

  void record(const dex::TraceEvent& e) override {
    if (whole_trace_) f_.events.push_back(e);
    if (e.event == "failsafe" && f_.abandoned_at < 0) f_.abandoned_at = e.t;
    if (e.event != "end") return;
    // Each end closes the oldest open run of its node on that drone (instances end in order).
    int drone = drone_index(e.drone);
    if (drone >= static_cast<int>(watch_.size())) return;
    int index = setup_.missions[drone].find(e.node, drone);
    if (index < 0) return;
    std::vector<std::size_t>& open = watch_[drone][index].open;
    if (open.empty()) return;
    ActionRun& a = f_.actions[open.front()];
    a.end = e.t;
    a.outcome = e.outcome;
    open.erase(open.begin());
  }

  /// The flight is over: each condition's last evaluation goes into the flight.
  void finish() {
    for (std::size_t d = 0; d < watch_.size(); ++d)
      for (NodeWatch& w : watch_[d]) {
        if (!w.seen.node) continue;
        ConditionSeen& kept = f_.conditions[{static_cast<int>(d), w.seen.node->meg}];
        if (!kept.node || kept.t <= w.seen.t) kept = std::move(w.seen);
      }
  }

 private:
  /// The watch of `node`, which drone `drone` runs: its engine runs setup_.missions[drone],
  /// so the node's place in that mission's nodes is its id.
  NodeWatch& watch(int drone, const dex::Node& node) {
    return watch_[drone].at(static_cast<std::size_t>(&node - setup_.missions[drone].nodes.data()));
  }

  int drone_index(const std::string& name) const {
    auto it = index_of_.find(name);
    return it == index_of_.end() ? static_cast<int>(setup_.missions[0].fleet.size()) : it->second;
  }

  std::vector<RangedRead> ranged_reads(const dex::Node& node) const {
    std::vector<const dex::Expr*> reads;
    collect_reads(node.condition, reads);
    std::vector<RangedRead> out;
    for (const dex::Expr* r : reads) {
      if (r->drone < 0 || r->drone >= static_cast<int>(setup_.missions.size())) continue;
      const fleet::SensorRange* range = setup_.c.fleet.sensor_range(setup_.missions[0].fleet[r->drone], r->property);
      if (range) out.push_back({r->drone, r->property, *range});
    }
    return out;
  }

  /// Which outcomes the condition can take with its ranged sensors anywhere in their ranges
  /// (the other values as read now): {can be false, can be true}.
  std::pair<bool, bool> possible(const dex::Node& node, const std::vector<RangedRead>& ranged,
                                 const dex::PropertyReader& read) const {
    std::vector<double> numbers;
    collect_numbers(node.condition, numbers);
    std::pair<bool, bool> can{false, false};
    // The first two ranged sensors are tried against each other; any further one takes the
    // first one's candidate position (rare in missions; documented in docs/verify.md).
    std::vector<std::vector<double>> values;
    for (const RangedRead& r : ranged) values.push_back(candidates(r.range, numbers));
    std::size_t n0 = values[0].size(), n1 = values.size() > 1 ? values[1].size() : 1;
    for (std::size_t i = 0; i < n0; ++i)
      for (std::size_t j = 0; j < n1; ++j) {
        auto substituted = [&](int d, const std::string& p) {
          for (std::size_t k = 0; k < ranged.size(); ++k)
            if (ranged[k].drone == d && ranged[k].sensor == p) {
              const std::vector<double>& vs = values[k];
              std::size_t idx = k == 1 ? j : i;
              return vs[std::min(idx, vs.size() - 1)];
            }
          return read(d, p);
        };
        (dex::evaluate(node.condition, substituted).boolean ? can.second : can.first) = true;
        if (can.first && can.second) return can;
      }
    return can;
  }

  /// An If, Repeat or Do whose first evaluation read a drone while it was moving: its
  /// outcome may differ when that drone is slower or faster (explore.cpp flies both).
  void note_timing(double t, int drone, const dex::Node& node, NodeWatch& w, bool value) {
    using lang::ControlKind;
    ControlKind k = node.control;
    if (k == ControlKind::WaitUntil || k == ControlKind::WaitWhile || k == ControlKind::PauseUntil ||
        k == ControlKind::PauseWhile || k == ControlKind::none)
      return;  // a wait ends either way; timing moves only when
    if (w.timing_noted || w.free == 1) return;
    std::vector<int> moving;
    for (const dex::Expr* r : w.reads) {
      if (r->drone < 0 || r->drone >= static_cast<int>(setup_.missions.size())) continue;
      if (r->property.rfind("Sensor", 0) == 0 || r->property == "Battery") continue;
      if (std::find(moving.begin(), moving.end(), r->drone) != moving.end()) continue;
      const ActionRun* a = running_at(f_, r->drone, t);
      if (a && a->motion) moving.push_back(r->drone);
    }
    if (moving.empty()) return;
    w.timing_noted = true;
    f_.timing_conditions.try_emplace({drone, node.meg}, value, std::move(moving));
  }

  bool decide(int drone, const dex::Node& node, NodeWatch& w, bool computed, const dex::PropertyReader& read) {
    if (w.free < 0) {
      std::vector<RangedRead> ranged = ranged_reads(node);
      bool is_free = false;
      if (!ranged.empty()) {
        auto [can_false, can_true] = possible(node, ranged, read);
        is_free = can_false && can_true;
      }
      w.free = is_free ? 1 : 0;
    }
    if (w.free == 0) return computed;
    std::pair<int, int> key{drone, node.meg};
    auto forced = forced_.find(key);
    bool value = forced == forced_.end() ? computed : forced->second;
    if (std::find(f_.decision_keys.begin(), f_.decision_keys.end(), key) == f_.decision_keys.end()) {
      f_.decision_keys.push_back(key);
      f_.decisions.push_back({setup_.missions[drone].fleet[drone], node.meg, node.line, node.col, node.text,
                              value, forced != forced_.end() && value != computed});
    }
    return value;
  }

  const Setup& setup_;
  const Assignment& forced_;
  Flight& f_;
  bool whole_trace_;
  std::unordered_map<std::string, int> index_of_;  ///< drone name → fleet index
  std::vector<std::vector<NodeWatch>> watch_;      ///< per drone, per node of its mission
};

/// Every drone flies in the built-in simulator, whatever adapter the fleet names: verify
/// never touches a vehicle. A factor f makes every motion and payload action take f times
/// as long (speeds / f, accelerations / f²). The site's rules are left out of the flight:
/// verify flies what the mission asks, so it can say at which action the mission breaks them
/// (in flight the drone refuses such an action or fails over, docs/faults.md).
void register_simulator(mid::AdapterRegistry& adapters, std::map<std::string, double> factors) {
  auto factory = [factors](const fleet::DroneSettings& s, const fleet::DroneType& t, mid::EventLoop& loop) {
    fleet::DroneSettings settings = s;
    settings.site = {};
    settings.gust.reset();
    double f = factors.count(s.name) ? factors.at(s.name) : 1.0;
    settings.limits.max_speed_mps /= f;
    settings.limits.max_climb_mps /= f;
    settings.limits.max_descent_mps /= f;
    settings.limits.max_accel_mps2 /= f * f;
    sim::SimOptions options;
    options.picture_s *= f;
    options.sensor_read_s *= f;
    mid::CreateResult r;
    r.drone = std::make_unique<sim::SimDrone>(settings, t, loop, options);
    return r;
  };
  adapters.register_adapter("sim", factory);
  adapters.register_adapter("mavlink", factory);
}

}  // namespace

Flight fly(const Setup& setup, const Assignment& forced, const std::vector<double>& factors, bool whole_trace) {
  Flight f;
  f.factors = factors;
  std::map<std::string, double> by_name;
  for (std::size_t d = 0; d < setup.missions.size(); ++d) by_name[setup.missions[d].settings.name] = factors[d];
  mid::AdapterRegistry adapters;
  register_simulator(adapters, by_name);
  Observer observer(setup, forced, f, whole_trace);
  dex::RunOptions options;
  options.time_limit_s = setup.options.time_limit_s;
  options.observer = &observer;
  // The mission as written: a plan that brings drones too close is what verify reports,
  // not what the give-way in flight would make of it.
  options.keep_separation = false;
  f.result = dex::run_in_process(setup.missions, adapters, &observer, options);
  observer.finish();
  return f;
}

const ActionRun* running_at(const Flight& f, int drone, double t) {
  const ActionRun* any = nullptr;
  const ActionRun* motion = nullptr;
  if (drone < 0 || static_cast<std::size_t>(drone) >= f.actions_of.size()) return nullptr;
  for (std::size_t i : f.actions_of[drone]) {
    const ActionRun& a = f.actions[i];
    if (a.start > t) break;  // in start order: none later runs at t
    if (a.end < t) continue;
    if (a.motion) motion = &a;
    else any = &a;
  }
  return motion ? motion : any;
}

}  // namespace eamos::verify
