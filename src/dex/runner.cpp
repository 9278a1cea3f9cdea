#include "dex/runner.h"

#include <cmath>

namespace eamos::dex {

namespace {

/// Delivers messages through the event loop, in send order, with no latency.
class InProcessTransport : public Transport {
 public:
  InProcessTransport(mid::EventLoop& loop, std::vector<std::unique_ptr<Engine>>& engines)
      : loop_(loop), engines_(engines) {}
  void send(int to, const Message& m) override {
    ++in_flight_;
    loop_.after(0.0, [this, to, m] {
      --in_flight_;
      engines_[to]->receive(m);
    });
  }
  int in_flight() const { return in_flight_; }

 private:
  mid::EventLoop& loop_;
  std::vector<std::unique_ptr<Engine>>& engines_;
  int in_flight_ = 0;
};

/// Appends `s` to `track` when position or phase differ from the last sample.
void record_sample(std::vector<Sample>& track, const mid::DroneState& s) {
  Sample now{s.t, s.x, s.y, s.z, s.armed, s.landed};
  if (!track.empty()) {
    const Sample& last = track.back();
    if (last.x == now.x && last.y == now.y && last.z == now.z && last.armed == now.armed &&
        last.landed == now.landed)
      return;
  }
  track.push_back(now);
}

}  // namespace

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
  // Telemetry board: the newest state each drone's broker published.
  std::vector<mid::DroneState> board(n);
  for (int d = 0; d < n; ++d) board[d] = drones[d]->state();
  std::vector<std::vector<Sample>> tracks(n);
  for (int d = 0; d < n; ++d) record_sample(tracks[d], board[d]);

  std::vector<std::unique_ptr<Engine>> engines;
  InProcessTransport transport(loop, engines);
  bool end_reached = false;
  bool failed = false;
  double finished_at = 0.0;
  auto check_done = [&] {
    if (!end_reached || failed || transport.in_flight() > 0) return;
    for (const auto& e : engines)
      if (e->busy()) return;
    result.completed = true;
    finished_at = loop.now();
    loop.stop();
  };
  auto fail = [&](const Failure& f) {
    if (failed) return;
    failed = true;
    finished_at = loop.now();
    result.failure = f;
    result.error = f.drone + "." + f.action + " (line " + std::to_string(f.line) + ") failed: " + f.reason;
    for (auto& e : engines) e->halt();
    for (int d = 0; d < n; ++d)
      if (!drones[d]->state().landed) drones[d]->failsafe(missions[d].settings.failsafe);
  };
  for (int d = 0; d < n; ++d) {
    EngineHooks hooks;
    hooks.transport = &transport;
    hooks.trace = trace;
    hooks.remote_property = [&board](int drone, const std::string& p) { return property_of(board[drone], p); };
    hooks.on_failure = fail;
    hooks.on_end = [&] {
      end_reached = true;
      loop.after(0.0, check_done);
    };
    engines.push_back(std::make_unique<Engine>(missions[d], *drones[d], loop, hooks));
  }
  for (int d = 0; d < n; ++d)
    drones[d]->subscribe([&, d](const mid::DroneState& s) {
      board[d] = s;
      record_sample(tracks[d], s);
      for (auto& e : engines) e->properties_changed(d);
      loop.after(0.0, check_done);
    });
  for (auto& e : engines) e->start();

  // Endless motions (an Orbit nobody preempts) keep the loop busy: bound the run.
  loop.run_until(options.time_limit_s);
  if (!result.completed && !failed) {
    loop.after(0.0, check_done);
    loop.run_until(loop.now());
  }
  if (!result.completed && !failed) {
    finished_at = loop.now();
    result.error = "mission did not complete within " + std::to_string(options.time_limit_s) + " s";
    for (auto& e : engines) e->halt();
    for (int d = 0; d < n; ++d)
      if (!drones[d]->state().landed) drones[d]->failsafe(missions[d].settings.failsafe);
  }
  if (failed || !result.completed) loop.run_until(loop.now() + 600.0);  // let failsafes finish
  result.duration = finished_at;
  for (int d = 0; d < n; ++d) {
    result.drones.push_back({missions[d].settings.name, drones[d]->state(), std::move(tracks[d])});
    result.activations += engines[d]->activations();
  }
  return result;
}

}  // namespace eamos::dex
