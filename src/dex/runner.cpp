#include "dex/runner.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <unordered_map>

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
    loop_.after(0.0, [this, &to, m] {
      --in_flight_;
      const std::vector<int>& clones = clones_of(m.meg, to);
      for (std::size_t i = 0; i < to.size(); ++i) {
        int d = to[i];
        if (d == m.from) continue;
        if (trace_messages_) trace_->record(message_event(missions_[d], m, d, loop_.now()));
        engines_[d]->receive_arrival(clones[i], m);  // one mission, one hash: checked at the start
      }
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
  /// The drones whose mission reads drone `d`'s telemetry.
  const std::vector<int>& readers_of(int d) const { return readers_[d]; }

 private:
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
  std::vector<std::vector<int>> readers_;  ///< per drone: the drones that read its telemetry
  std::function<void()> on_delivered_;
  int in_flight_ = 0;  ///< triggers and cancels sent, not yet handled
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

/// Runs the loop on after an abandoned mission until every drone's failsafe is over
/// (failsafe_over). The first look comes after the callbacks already queued, the ends of
/// the actions the failsafes cancelled among them, so those are traced; later looks every
/// 0.1 mission s stop the loop at once: a real-time loop would otherwise wait for input
/// until its limit, and a MAVLink drone's heartbeats never leave it idle.
void wait_for_failsafes(mid::EventLoop& loop, const std::vector<std::unique_ptr<mid::Drone>>& drones,
                        const std::vector<Mission>& missions) {
  const double since = loop.now();
  mid::TimerId next = mid::kNoTimer;
  std::function<void()> look = [&] {
    for (std::size_t d = 0; d < drones.size(); ++d)
      if (!failsafe_over(drones[d]->state(), missions[d].settings.failsafe, loop.now() - since)) {
        next = loop.after(0.1, look);
        return;
      }
    next = mid::kNoTimer;
    loop.stop();
  };
  next = loop.after(0.0, look);
  loop.run_until(since + kFailsafeWaitLimitS);
  loop.cancel(next);  // it refers to this frame
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

TraceEvent mission_end_event(const RunResult& r) {
  TraceEvent e;
  e.t = r.duration;
  e.event = "mission";
  e.outcome = r.completed ? "completed" : "failed";
  e.reason = r.completed ? "" : r.error;
  return e;
}

bool command_failsafe(mid::Drone& drone, const fleet::DroneSettings& settings) {
  mid::DroneState s = drone.state();
  if (down_and_disarmed(s)) return false;  // already safe; an armed drone on the ground is disarmed
  drone.failsafe(settings.failsafe);
  return true;
}

void record_failsafe(const fleet::DroneSettings& settings, double t, const std::string& reason, TraceSink* trace) {
  if (!trace) return;
  TraceEvent e;
  e.t = t;
  e.drone = settings.name;
  e.event = "failsafe";
  e.name = fleet::failsafe_name(settings.failsafe);
  e.reason = reason;
  trace->record(e);
}

bool failsafe_over(const mid::DroneState& s, fleet::Failsafe failsafe, double waited_s) {
  if (down_and_disarmed(s) || s.link_lost || waited_s >= kFailsafeWaitLimitS) return true;
  // On the ground every failsafe disarms: that is still to come for an armed drone there.
  return failsafe == fleet::Failsafe::hover && !s.landed;
}

void enter_failsafe(mid::Drone& drone, const fleet::DroneSettings& settings, double t, const std::string& reason,
                    TraceSink* trace) {
  // Command first: a trace write (a DDS sample, a pipe) may block, the drone must not wait.
  if (command_failsafe(drone, settings)) record_failsafe(settings, t, reason, trace);
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

RunResult run_in_process(const std::vector<Mission>& missions, const mid::AdapterRegistry& adapters,
                         TraceSink* trace, const RunOptions& options) {
  RunResult result;
  int n = static_cast<int>(missions.size());
  for (int d = 0; d < n; ++d)
    if (missions[d].hash != missions[0].hash || missions[d].self != d) {
      result.error = "mission files do not belong to one mission (hash or drone order differs)";
      return result;
    }
  mid::EventLoop loop(options.clock);
  std::vector<std::unique_ptr<mid::Drone>> drones;
  for (const Mission& m : missions) {
    mid::CreateResult c = adapters.create(m.settings.adapter, m.settings, m.type, loop);
    if (c.status != mid::CreateStatus::success) {
      result.error = m.settings.name + ": " + c.message;
      return result;
    }
    drones.push_back(std::move(c.drone));
  }
  std::vector<mid::Drone*> connected;
  std::vector<fleet::DroneSettings> declared;
  for (int d = 0; d < n; ++d) connected.push_back(drones[d].get()), declared.push_back(missions[d].settings);
  if (std::string wrong = mid::check_homes_at_connect(loop, connected, declared, mid::kHomeFixTimeoutS);
      !wrong.empty()) {
    result.error = "the vehicles do not stand where the fleet file puts them; nothing was armed:\n" + wrong;
    return result;
  }
  std::vector<std::vector<Sample>> tracks(n);
  for (int d = 0; d < n; ++d) record_sample(tracks[d], drones[d]->state());

  std::vector<std::unique_ptr<Engine>> engines;
  bool end_reached = false;
  bool failed = false;
  double finished_at = 0.0;
  // Checked whenever an engine settles idle and after every delivered message: the mission
  // completes at that instant, not at the next event that happens to come by.
  std::function<void()> check_done;
  InProcessTransport transport(loop, engines, missions, trace, [&] { check_done(); });
  check_done = [&] {
    if (!end_reached || failed || result.completed || transport.in_flight() > 0) return;
    for (const auto& e : engines)
      if (e->busy()) return;
    result.completed = true;
    finished_at = loop.now();
    loop.stop();
  };
  // The mission is over without completing: start nothing more, land (or whatever the
  // fleet file says) every drone still in the air. Every drone is commanded before any
  // failsafe is recorded: a trace write may block.
  bool abandoned = false;
  auto abandon = [&] {
    if (abandoned) return;
    abandoned = true;
    for (auto& e : engines) e->halt();
    std::vector<bool> commanded(n);
    for (int d = 0; d < n; ++d) commanded[d] = command_failsafe(*drones[d], missions[d].settings);
    for (int d = 0; d < n; ++d)
      if (commanded[d]) record_failsafe(missions[d].settings, loop.now(), result.error, trace);
  };
  // Interrupted (Ctrl-C) or a failure inside the executor itself rather than in an action.
  auto stop_mission = [&](const std::string& why) {
    if (failed || result.completed || abandoned) return;
    failed = true;
    finished_at = loop.now();
    result.error = why;
    abandon();
    loop.stop();
  };
  auto fail = [&](const Failure& f) {
    if (failed || abandoned) return;
    failed = true;
    finished_at = loop.now();
    result.failure = f;
    result.error = failure_text(f);
    abandon();
    loop.stop();  // a real-time loop would otherwise wait out the time limit; failsafes run below
  };
  loop.on_callback_error([&](const std::string& what) {
    std::cerr << "eamos: internal error in the executor: " << what << "\n";
    stop_mission("internal error in the executor: " + what);
  });
  for (int d = 0; d < n; ++d) {
    EngineHooks hooks;
    hooks.transport = &transport;
    hooks.trace = trace;
    hooks.on_failure = fail;
    hooks.on_end = [&] { end_reached = true; };  // the lead's engine settles next: check_done then
    hooks.on_idle = [&] { check_done(); };
    hooks.observer = options.observer;
    engines.push_back(std::make_unique<Engine>(missions[d], *drones[d], loop, hooks));
  }
  // Each drone's broker feeds its own engine directly and every other drone through the
  // transport (the OutBridge side of telemetry); a first publication seeds every board.
  // Before anything runs, every engine holds the initial state of every drone it reads, as
  // a DEX does after the start barrier: a condition at t = 0 never reads a value that is
  // not there yet. One shared copy per drone: a fleet of k is k copies, not k².
  for (int d = 0; d < n; ++d) {
    auto initial = std::make_shared<const Telemetry>(Telemetry{missions[d].hash, d, drones[d]->state()});
    for (int to : transport.readers_of(d))
      if (to != d) engines[to]->receive(initial);
  }
  for (int d = 0; d < n; ++d) {
    drones[d]->subscribe([&, d](const mid::DroneState& s) {
      if (options.keep_tracks) record_sample(tracks[d], s);
      engines[d]->properties_changed(d);
      if (!transport.readers_of(d).empty())
        transport.publish(std::make_shared<const Telemetry>(Telemetry{missions[d].hash, d, s}));
    });
  }
  if (options.interrupt) options.interrupt->attach(loop, stop_mission);
  TelemetryRecorder telemetry(trace, options.telemetry_hz);
  if (telemetry.enabled()) sample_fleet(loop, telemetry, drones, 0);
  for (auto& e : engines) e->start();

  // Endless motions (an Orbit nobody preempts) keep the loop busy: bound the run.
  loop.run_until(options.time_limit_s);
  if (!result.completed && !failed) {
    finished_at = loop.now();
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g", options.time_limit_s);
    result.error = std::string("mission did not complete within ") + limit +
                   " s of mission time; raise --time-limit if it is meant to run longer";
    abandon();
  }
  if (failed || !result.completed) wait_for_failsafes(loop, drones, missions);
  if (options.interrupt) options.interrupt->detach();
  result.duration = finished_at;
  for (int d = 0; d < n; ++d) {
    if (!options.keep_tracks) record_sample(tracks[d], drones[d]->state());
    result.drones.push_back({missions[d].settings.name, drones[d]->state(), std::move(tracks[d])});
    result.activations += engines[d]->activations();
  }
  trace_mission_end(trace, result);
  return result;
}

}  // namespace eamos::dex
