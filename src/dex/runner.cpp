#include "dex/runner.h"

#include "dex/separation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <set>
#include <unordered_map>
#include <utility>

#include "diag/log.h"
#include "diag/number.h"
#include "mid/home_check.h"

namespace eamos::dex {

namespace {

/// Delivers messages through the event loop, in send order, with no latency. Telemetry
/// goes only to the drones whose mission reads the sender (Mission::reads), the way a DDS
/// reader subscribes to what it needs. `on_delivered` runs after each message is handled:
/// the last message in flight may be what completes the mission. Only triggers and cancels
/// count as in flight: a sample cannot start anything in a fleet whose engines are all idle
/// (no condition is watched), and a still, armed vehicle publishes for ever, so a sample on
/// its way when the last engine settled kept the run waiting for its time limit.
class InProcessTransport : public Transport {
 public:
  InProcessTransport(mid::EventLoop& loop, std::vector<std::unique_ptr<Engine>>& engines,
                     const std::vector<Mission>& missions, TraceSink* trace, std::function<void()> on_delivered)
      : loop_(loop), engines_(engines), missions_(missions), trace_(trace),
        trace_messages_(trace && trace->takes_messages()), readers_(missions.size()),
        on_delivered_(std::move(on_delivered)) {
    for (std::size_t to = 0; to < missions.size(); ++to)
      for (int d : missions[to].reads)
        if (d >= 0 && d < static_cast<int>(readers_.size())) readers_[d].push_back(static_cast<int>(to));
  }
  void send(int to, const Message& m) override {
    ++in_flight_;
    loop_.after(0.0, [this, to, m] {
      --in_flight_;
      deliver(to, m);
      on_delivered_();
    });
  }
  /// One event for the whole set, in the set's order: a fleet-wide barrier schedules k
  /// events, not k².
  void send_to_set(const std::vector<int>& to, const Message& m) override {
    ++in_flight_;
    Barrier* b = counted_barrier(to, m);
    if (b) announced(*b, m.from);
    loop_.after(0.0, [this, &to, m, b] {
      --in_flight_;
      // Another set may have reached the barrier since: every engine was told its count
      // then, and from then on hears of each arrival, this one too.
      if (b && !b->each) deliver_counted(*b, m);
      else deliver_each(to, m);
      on_delivered_();
    });
  }
  void publish(std::shared_ptr<const Telemetry> t) override {
    for (int to : readers_[t->from]) {
      if (to == t->from) continue;
      loop_.after(0.0, [this, to, t] { engines_[to]->receive(t); });
    }
  }
  int in_flight() const { return in_flight_; }
  std::uint64_t set_delivery_steps() const { return set_steps_; }
  /// The drones whose mission reads drone `d`'s telemetry.
  const std::vector<int>& readers_of(int d) const { return readers_[d]; }

 private:
  /// A sync point outside every Repeat/Do body (reached once per drone) whose arrivals all go
  /// to one set, in a run whose trace keeps no messages. Its clones' arrivals are counted
  /// here, and an engine hears of them only when it matters: when it arrives itself (it
  /// learns how many came before) and when the last arrival it waits for comes (the barrier
  /// passes, at the same instant and in the same order as with every arrival delivered). A
  /// delivery looks only at the drones it must tell, not at the whole set: a fleet-wide
  /// barrier costs O(k log k), where k engine calls per arrival cost k², and a loop over the
  /// set per arrival still k² cheap steps (5·10⁹ for 52 barriers of 10,000 drones).
  struct Barrier {
    const std::vector<int>* to = nullptr;  ///< interned (deploy::FleetTables): one set, one address
    std::vector<int> clones;     ///< per drone of `to`: its clone's node index, or -1
    std::vector<char> counted;   ///< the clone's arrivals are counted here
    std::vector<char> arrived;   ///< its drone has arrived (announced) itself
    std::vector<int> missing;    ///< at its drone's arrival: arrivals it still waited for
    std::vector<long long> pass_at;  ///< while it waits: the delivery (by number) it passes at
    long long delivered = 0;     ///< arrivals delivered so far: what a drone not yet arrived is untold
    std::set<std::pair<long long, int>> due;  ///< (pass_at, i) of the drones still waiting
    std::set<int> every;         ///< told of every delivery: clones not counted, drones no longer waiting
    bool each = false;           ///< another set reached it: every arrival goes to every engine
  };

  Barrier* counted_barrier(const std::vector<int>& to, const Message& m) {
    if (trace_messages_ || m.scope >= 0 || m.body_epoch != 0) return nullptr;
    auto [it, added] = barriers_.try_emplace(m.meg);
    Barrier& b = it->second;
    if (added) start_barrier(b, to, m.meg);
    if (!b.each && b.to != &to) tell_all(b);
    return b.each ? nullptr : &b;
  }

  void start_barrier(Barrier& b, const std::vector<int>& to, int meg) {
    b.to = &to;
    std::size_t k = to.size();
    b.counted.assign(k, 0), b.arrived.assign(k, 0), b.missing.assign(k, 0), b.pass_at.assign(k, -1);
    for (std::size_t i = 0; i < k; ++i) {
      int clone = missions_[to[i]].find(meg, to[i]);
      b.clones.push_back(clone);
      if (clone < 0) continue;
      const Node& n = missions_[to[i]].nodes[clone];
      // Counted only where the engine's own arrival is what readies it (dex::Engine::arrive).
      b.counted[i] = n.scope < 0 && n.internal && n.notify >= 0 && n.exec_in > 0 && n.waits_count > 0;
      if (!b.counted[i]) b.every.insert(static_cast<int>(i));
    }
  }

  /// Arrivals counted here for drone `i` and not yet told its engine.
  static long long untold(const Barrier& b, std::size_t i) {
    if (!b.counted[i]) return 0;
    if (!b.arrived[i]) return b.delivered;
    // Waiting: its pass_at lies `missing` deliveries (not its own) after its arrival.
    return b.pass_at[i] < 0 ? 0 : b.missing[i] - (b.pass_at[i] - b.delivered);
  }

  /// Tells every engine what was counted for it and delivers each arrival from now on.
  void tell_all(Barrier& b) {
    for (std::size_t i = 0; i < b.clones.size(); ++i)
      if (long long n = untold(b, i); n > 0) engines_[(*b.to)[i]]->add_arrivals(b.clones[i], static_cast<int>(n));
    b.each = true;
  }

  /// Drone `d` arrives (inside its engine's arrive(), before it looks at its count): its
  /// engine learns the arrivals counted so far, and from now on it waits for the delivery
  /// that brings the last arrival it lacks.
  void announced(Barrier& b, int d) {
    auto at = std::lower_bound(b.to->begin(), b.to->end(), d);
    if (at == b.to->end() || *at != d) return;
    std::size_t i = at - b.to->begin();
    if (!b.counted[i]) return;
    b.missing[i] = engines_[d]->add_arrivals(b.clones[i], static_cast<int>(b.delivered));
    b.arrived[i] = 1;
    if (b.missing[i] <= 1) {
      b.every.insert(static_cast<int>(i));
      return;
    }
    b.pass_at[i] = b.delivered + b.missing[i];
    b.due.emplace(b.pass_at[i], static_cast<int>(i));
  }

  void deliver_counted(Barrier& b, const Message& m) {
    const std::vector<int>& to = *b.to;
    auto from = std::lower_bound(to.begin(), to.end(), m.from);
    if (from != to.end() && *from == m.from) {
      std::size_t f = from - to.begin();
      if (b.pass_at[f] >= 0 && b.due.erase({b.pass_at[f], static_cast<int>(f)}) > 0)
        b.due.emplace(++b.pass_at[f], static_cast<int>(f));  // its own arrival is none it waits for
    }
    ++b.delivered;
    std::vector<int> passing;  // the drones this delivery brings their last awaited arrival
    while (!b.due.empty() && b.due.begin()->first == b.delivered) {
      passing.push_back(b.due.begin()->second);
      b.due.erase(b.due.begin());
    }
    std::vector<int> all;  // in the set's order, as a delivery to each drone would reach them
    std::merge(b.every.begin(), b.every.end(), passing.begin(), passing.end(), std::back_inserter(all));
    set_steps_ += all.size();
    for (int i : all) {
      int d = to[i];
      if (d == m.from || b.clones[i] < 0) continue;
      if (b.pass_at[i] >= 0) {
        if (b.missing[i] > 1) engines_[d]->add_arrivals(b.clones[i], b.missing[i] - 1);
        b.pass_at[i] = -1;
        b.every.insert(i);
      }
      engines_[d]->count_arrival(b.clones[i], m);  // the last one it waits for: it passes
    }
  }

  void deliver_each(const std::vector<int>& to, const Message& m) {
    const std::vector<int>& clones = clones_of(m.meg, to);
    set_steps_ += to.size();
    for (std::size_t i = 0; i < to.size(); ++i) {
      int d = to[i];
      if (d == m.from) continue;
      if (trace_messages_) trace_->record(message_event(missions_[d], m, d, loop_.now()));
      engines_[d]->count_arrival(clones[i], m);  // one mission, one hash: checked at the start
    }
  }

  /// Where each drone of `to` holds its clone of sync point `meg`, found once per sync point:
  /// a fleet-wide barrier delivers every arrival to every drone.
  const std::vector<int>& clones_of(int meg, const std::vector<int>& to) {
    std::vector<int>& clones = clones_[meg];
    if (clones.size() != to.size()) {
      clones.clear();
      for (int d : to) clones.push_back(missions_[d].find(meg, d));
    }
    return clones;
  }

  void deliver(int to, const Message& m) {
    if (trace_messages_) trace_->record(message_event(missions_[to], m, to, loop_.now()));
    engines_[to]->receive(m);
  }

  mid::EventLoop& loop_;
  std::vector<std::unique_ptr<Engine>>& engines_;
  const std::vector<Mission>& missions_;
  TraceSink* trace_;
  bool trace_messages_;
  std::unordered_map<int, std::vector<int>> clones_;  ///< sync point → clone index per drone of its set
  std::unordered_map<int, Barrier> barriers_;  ///< by sync point (MEG id): see Barrier
  std::vector<std::vector<int>> readers_;  ///< per drone: the drones that read its telemetry
  std::function<void()> on_delivered_;
  int in_flight_ = 0;  ///< triggers and cancels sent, not yet handled
  std::uint64_t set_steps_ = 0;  ///< RunResult::set_delivery_steps
};

/// The trace's last event: how the mission ended, at the instant it did.
void trace_mission_end(TraceSink* trace, const RunResult& r) {
  if (trace) trace->record(mission_end_event(r));
}

/// Samples every drone at slot `tick` of the telemetry rate, and so on until the loop stops.
void sample_fleet(mid::EventLoop& loop, TelemetryRecorder& recorder,
                  const std::vector<std::unique_ptr<mid::Drone>>& drones, long long tick) {
  double t = tick * recorder.period();
  for (const auto& d : drones) recorder.sample(d->name(), d->state(), t);
  loop.at((tick + 1) * recorder.period(), [&loop, &recorder, &drones, tick] {
    sample_fleet(loop, recorder, drones, tick + 1);
  });
}

}  // namespace

TraceEvent message_event(const Mission& receiver, const Message& m, int to, double received) {
  TraceEvent e;
  e.t = received;
  e.event = "message";
  e.kind = m.kind == Message::Kind::cancel ? "cancel" : "trigger";
  e.from = m.from;
  e.to = to;
  e.node = m.meg;
  // A drone's arrival at a sync point triggers the receiver's own clone of it.
  if (m.kind == Message::Kind::arrived) e.instance = to;
  e.sent = m.sent;
  if (to >= 0 && to < static_cast<int>(receiver.fleet.size())) e.drone = receiver.fleet[to];
  return e;
}

void TelemetryRecorder::sample(const std::string& name, const mid::DroneState& s, double t) {
  if (!enabled()) return;
  auto it = last_.find(name);
  if (it != last_.end()) {
    const mid::DroneState& l = it->second;
    bool same_heading = l.heading == s.heading || (std::isnan(l.heading) && std::isnan(s.heading));
    if (l.x == s.x && l.y == s.y && l.z == s.z && l.armed == s.armed && l.landed == s.landed &&
        l.battery == s.battery && l.mode == s.mode && same_heading)
      return;
  }
  last_[name] = s;
  TraceEvent e;
  e.t = t;
  e.event = "telemetry";
  e.drone = name;
  e.state = s;
  trace_->record(e);
}

bool TelemetryRecorder::due(const std::string& name, double t) {
  if (!enabled()) return false;
  double& next = next_[name];
  if (t < next) return false;
  next = (std::floor(t * hz_ + 1e-9) + 1) / hz_;
  return true;
}

std::vector<std::string> run_warnings(const RunResult& r, const std::string& pace) {
  std::vector<std::string> out;
  char text[32];
  for (const DroneSummary& d : r.drones) {
    if (!r.completed || !d.final || down_and_disarmed(d.state)) continue;
    if (!d.state.landed) {
      std::snprintf(text, sizeof text, "%.1f", d.state.z);
      out.push_back(d.name + " is still in the air when the mission ends (z = " + text + " m) and nothing lands it; " +
                    "end its part with " + d.name + ".Land() and " + d.name +
                    ".Disarm() (eamos verify reports this as airborne_at_end)");
    } else {
      out.push_back(d.name + " is still armed on the ground when the mission ends; end its part with " + d.name +
                    ".Disarm() (eamos verify reports this as armed_at_end)");
    }
  }
  if (r.max_lag > 0.1) {  // less is the jitter of any run on a busy host
    std::snprintf(text, sizeof text, "%.2f", r.max_lag);
    out.push_back("the host could not keep up with " + pace + ": events ran up to " + text +
                  " s of mission time late, and this run's timing strays from the plan's by as much; use a lower "
                  "speed, or leave it out to run on virtual time (the plan's timing, as fast as the host can)");
  }
  return out;
}

TraceEvent mission_end_event(const RunResult& r) {
  TraceEvent e;
  e.t = r.duration;
  e.event = "mission";
  e.outcome = r.completed ? "completed" : "failed";
  e.reason = r.completed ? "" : r.error;
  return e;
}

void RunInterrupt::request(const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (over_) return;
  if (!loop_) {
    if (!pending_) pending_ = reason;
    return;
  }
  // on_request_ is copied: detach() may clear it before the loop runs this.
  loop_->post([fn = on_request_, reason] { fn(reason); });
}

void RunInterrupt::attach(mid::EventLoop& loop, std::function<void(const std::string&)> on_request) {
  std::lock_guard<std::mutex> lock(mutex_);
  loop_ = &loop;
  on_request_ = std::move(on_request);
  if (pending_) loop_->post([fn = on_request_, reason = *pending_] { fn(reason); });
  pending_.reset();
}

bool RunInterrupt::running() {
  std::lock_guard<std::mutex> lock(mutex_);
  return loop_ != nullptr;
}

bool RunInterrupt::over() {
  std::lock_guard<std::mutex> lock(mutex_);
  return over_;
}

void RunInterrupt::detach() {
  std::lock_guard<std::mutex> lock(mutex_);
  loop_ = nullptr;
  on_request_ = nullptr;
  over_ = true;  // the run is over: later requests change nothing
}

void record_sample(std::vector<Sample>& track, const mid::DroneState& s) {
  Sample now{s.t, s.x, s.y, s.z, s.armed, s.landed, s.battery};
  if (!track.empty()) {
    const Sample& last = track.back();
    if (last.x == now.x && last.y == now.y && last.z == now.z && last.armed == now.armed &&
        last.landed == now.landed)
      return;
  }
  track.push_back(now);
}


namespace {

/// One run of a whole mission in this process: its loop, drones, engines and transport, and
/// how it ends (completed, failed, interrupted, out of time). run_in_process is its one user.
class InProcessRun {
 public:
  InProcessRun(const std::vector<Mission>& missions, TraceSink* trace, const RunOptions& options)
      : missions_(missions), trace_(trace), options_(options), n_(static_cast<int>(missions.size())),
        loop_(options.clock), tracks_(missions.size()),
        transport_(loop_, engines_, missions, trace, [this] { check_done(); }),
        telemetry_(trace, options.telemetry_hz) {}

  RunResult run(const mid::AdapterRegistry& adapters);

 private:
  bool one_mission();
  bool make_drones(const mid::AdapterRegistry& adapters);
  bool homes_agree();
  void make_engines();
  void seed_boards();
  void subscribe_drones();
  void fly();
  void check_done();
  void stop_mission(const std::string& why);
  void fail(const Failure& f);
  void abandon();
  void summarise();

  const std::vector<Mission>& missions_;
  TraceSink* trace_;
  const RunOptions& options_;
  const int n_;
  RunResult result_;
  mid::EventLoop loop_;
  std::vector<std::unique_ptr<mid::Drone>> drones_;
  std::vector<std::vector<Sample>> tracks_;
  std::vector<std::unique_ptr<Engine>> engines_;
  /// Whether each engine watches a condition (EngineHooks::watching): a drone's motion step
  /// looks here, not at its cold engine, to learn that no condition waits on it.
  std::unique_ptr<bool[]> watching_;
  InProcessTransport transport_;
  TelemetryRecorder telemetry_;
  bool end_reached_ = false;
  bool failed_ = false;
  bool abandoned_ = false;
  double finished_at_ = 0.0;
  std::unique_ptr<SeparationGuard> separation_;  ///< last: it holds timers on loop_
};

RunResult InProcessRun::run(const mid::AdapterRegistry& adapters) {
  if (!one_mission() || !make_drones(adapters) || !homes_agree()) return result_;
  for (int d = 0; d < n_; ++d) record_sample(tracks_[d], drones_[d]->state());
  loop_.on_callback_error([this](const std::string& what) {
    diag::Logger{"dex", ""}.error("internal error in the executor: " + what);
    stop_mission("internal error in the executor: " + what);
  });
  make_engines();
  seed_boards();
  subscribe_drones();
  fly();
  result_.max_lag = loop_.max_lag();
  summarise();
  trace_mission_end(trace_, result_);
  return result_;
}

bool InProcessRun::one_mission() {
  for (int d = 0; d < n_; ++d)
    if (missions_[d].hash != missions_[0].hash || missions_[d].self != d) {
      result_.error = "mission files do not belong to one mission (hash or drone order differs)";
      return false;
    }
  return true;
}

bool InProcessRun::make_drones(const mid::AdapterRegistry& adapters) {
  for (const Mission& m : missions_) {
    mid::CreateResult c = adapters.create(m.settings.adapter, m.settings, m.type, loop_);
    if (c.status != mid::CreateStatus::success) {
      result_.error = m.settings.name + ": " + c.message;
      return false;
    }
    drones_.push_back(std::move(c.drone));
  }
  return true;
}

// The vehicles stand where the fleet file puts them, relative to each other (mid/home_check.h),
// or nothing arms.
bool InProcessRun::homes_agree() {
  std::vector<mid::Drone*> connected;
  std::vector<fleet::DroneSettings> declared;
  for (int d = 0; d < n_; ++d) connected.push_back(drones_[d].get()), declared.push_back(missions_[d].settings);
  std::string wrong = mid::check_homes_at_connect(loop_, connected, declared, mid::kHomeFixTimeoutS);
  if (wrong.empty()) return true;
  result_.error = "the vehicles do not stand where the fleet file puts them; nothing was armed:\n" + wrong;
  return false;
}

void InProcessRun::make_engines() {
  watching_ = std::make_unique<bool[]>(static_cast<std::size_t>(n_));  // all false
  for (int d = 0; d < n_; ++d) {
    EngineHooks hooks;
    hooks.transport = &transport_;
    hooks.trace = trace_;
    hooks.on_failure = [this](const Failure& f) { fail(f); };
    hooks.on_end = [this] { end_reached_ = true; };  // the lead's engine settles next: check_done then
    hooks.on_idle = [this] { check_done(); };
    hooks.observer = options_.observer;
    hooks.watching = &watching_[d];
    engines_.push_back(std::make_unique<Engine>(missions_[d], *drones_[d], loop_, hooks));
  }
}

// Before anything runs, every engine holds the initial state of every drone it reads, as
// a DEX does after the start barrier: a condition at t = 0 never reads a value that is not
// there yet. One shared copy per drone: a fleet of k is k copies, not k².
void InProcessRun::seed_boards() {
  for (int d = 0; d < n_; ++d) {
    auto initial = std::make_shared<const Telemetry>(Telemetry{missions_[d].hash, d, drones_[d]->state()});
    for (int to : transport_.readers_of(d))
      if (to != d) engines_[to]->receive(initial);
  }
}

// Each drone's broker feeds its own engine directly and every other drone through the
// transport (the OutBridge side of telemetry).
void InProcessRun::subscribe_drones() {
  if (options_.keep_separation) {
    separation_ = std::make_unique<SeparationGuard>(
        missions_[0], loop_, SeparationHooks{trace_, [this](const std::string& why) { stop_mission(why); }});
    for (int d = 0; d < n_; ++d) {
      separation_->fly(d, *drones_[d], missions_[d].settings.limits);
      separation_->update(d, drones_[d]->state());
    }
  }
  for (int d = 0; d < n_; ++d) {
    drones_[d]->subscribe([this, d](const mid::DroneState& s) {
      if (options_.keep_tracks) record_sample(tracks_[d], s);
      if (separation_) separation_->update(d, s);
      if (watching_[d]) engines_[d]->properties_changed(d);
      if (!transport_.readers_of(d).empty())
        transport_.publish(std::make_shared<const Telemetry>(Telemetry{missions_[d].hash, d, s}));
    });
  }
}

void InProcessRun::fly() {
  if (options_.interrupt) options_.interrupt->attach(loop_, [this](const std::string& why) { stop_mission(why); });
  if (telemetry_.enabled()) sample_fleet(loop_, telemetry_, drones_, 0);
  for (auto& e : engines_) e->start();
  // Endless motions (an Orbit nobody preempts) keep the loop busy: bound the run.
  loop_.run_until(options_.time_limit_s);
  if (!result_.completed && !failed_) {
    finished_at_ = loop_.now();
    result_.error = "mission did not complete within " + diag::number_text(options_.time_limit_s) +
                    " s of mission time; raise --time-limit if it is meant to run longer";
    abandon();
  }
  if (abandoned_) {
    std::vector<FailsafeDrone> fleet;
    for (int d = 0; d < n_; ++d) fleet.push_back({engines_[d].get(), drones_[d].get(), &missions_[d].settings});
    FailsafeWait wait(loop_, std::move(fleet), 0.1, [this] { loop_.stop(); }, trace_);
    wait.start();
    loop_.run_until(loop_.now() + kFailsafeWaitLimitS);
  }
  if (options_.interrupt) options_.interrupt->detach();
}

// Checked whenever an engine settles idle and after every delivered message: the mission
// completes at that instant, not at the next event that happens to come by.
void InProcessRun::check_done() {
  if (!end_reached_ || failed_ || result_.completed || transport_.in_flight() > 0) return;
  for (const auto& e : engines_)
    if (e->busy()) return;
  result_.completed = true;
  finished_at_ = loop_.now();
  loop_.stop();
}

// Interrupted (Ctrl-C) or a failure inside the executor itself rather than in an action.
void InProcessRun::stop_mission(const std::string& why) {
  if (failed_ || result_.completed || abandoned_) return;
  failed_ = true;
  finished_at_ = loop_.now();
  result_.error = why;
  abandon();
  loop_.stop();
}

void InProcessRun::fail(const Failure& f) {
  if (failed_ || abandoned_) return;
  failed_ = true;
  finished_at_ = loop_.now();
  result_.failure = f;
  result_.error = failure_text(f);
  abandon();
  loop_.stop();  // a real-time loop would otherwise wait out the time limit; failsafes run in fly()
}

// The mission is over without completing: start nothing more, and every drone still in the
// air runs its failsafe.
void InProcessRun::abandon() {
  if (abandoned_) return;
  abandoned_ = true;
  if (separation_) separation_->halt();
  std::vector<FailsafeDrone> fleet;
  for (int d = 0; d < n_; ++d) fleet.push_back({engines_[d].get(), drones_[d].get(), &missions_[d].settings});
  abandon_drones(fleet, loop_.now(), result_.error, trace_);
}

void InProcessRun::summarise() {
  result_.duration = finished_at_;
  for (int d = 0; d < n_; ++d) {
    if (!options_.keep_tracks) record_sample(tracks_[d], drones_[d]->state());
    result_.drones.push_back({missions_[d].settings.name, drones_[d]->state(), std::move(tracks_[d])});
    result_.activations += engines_[d]->activations();
  }
  result_.set_delivery_steps = transport_.set_delivery_steps();
}

}  // namespace

RunResult run_in_process(const std::vector<Mission>& missions, const mid::AdapterRegistry& adapters,
                         TraceSink* trace, const RunOptions& options) {
  return InProcessRun(missions, trace, options).run(adapters);
}

}  // namespace eamos::dex
