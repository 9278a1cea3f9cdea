#pragma once
// Runs a whole compiled mission in one process: one DEX engine per drone, each with its
// own drone from the Adapter Space, all on one event loop, talking through the in-process
// transport. The mission completes when the end node ran and nothing is active on any
// drone; the first failed action fails it, and every airborne drone runs its failsafe.
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "dex/engine.h"
#include "dex/failsafe.h"
#include "dex/latency.h"
#include "dex/mission.h"
#include "dex/observer.h"
#include "mid/adapter_registry.h"
#include "mid/event_loop.h"

namespace eamos::dex {

/// Lets another thread end a running mission early: the signal watcher of `eamos run` on
/// Ctrl-C or SIGTERM. The run abandons the mission like a failed one (every drone runs its
/// failsafe, the run returns once they are down) with the request's reason.
class RunInterrupt {
 public:
  /// Thread-safe, at any time. Before the run started it is abandoned as soon as it starts;
  /// after it ended (or while it already lands every drone) this changes nothing.
  void request(const std::string& reason);
  /// For run_in_process: requests go to `on_request`, on `loop`'s thread, from now on.
  void attach(mid::EventLoop& loop, std::function<void(const std::string&)> on_request);
  void detach();
  /// Whether a run is going on (attached) or over (detached): what a request does now.
  bool running();
  bool over();

 private:
  std::mutex mutex_;
  mid::EventLoop* loop_ = nullptr;
  std::function<void(const std::string&)> on_request_;
  std::optional<std::string> pending_;
  bool over_ = false;
};

struct RunOptions {
  mid::ClockOptions clock;
  double time_limit_s = 3600.0;  ///< a mission still running then fails ("did not finish")
  RunInterrupt* interrupt = nullptr;
  RunObserver* observer = nullptr;  ///< `eamos verify` only (dex/observer.h)
  double telemetry_hz = 0.0;  ///< telemetry events in the trace per mission second; 0 = none
  /// Keep each drone's track (a sample per change of position or phase: 20 per second of
  /// flight) in the result, for verify's checks and the plot. Off, a track holds the
  /// drone's first and last state only: a 1,000-drone show flies 18 million samples.
  bool keep_tracks = true;
  /// Keep the fleet's min_separation in flight: drones give way (dex/separation.h). Off for
  /// `eamos verify`, which flies the mission as written to find where it plans drones too close.
  bool keep_separation = true;
};

/// One drone's position and phase at a moment its broker published a change of them.
struct Sample {
  double t;        ///< mission seconds
  double x, y, z;  ///< m east, north, up of the mission origin
  bool armed;
  bool landed;
  double battery;  ///< %
};

/// Appends `s` to `track` when position or phase differ from the last sample.
void record_sample(std::vector<Sample>& track, const mid::DroneState& s);

struct DroneSummary {
  std::string name;
  mid::DroneState state;       ///< at the end of the run (or as last seen, when not final)
  std::vector<Sample> track;   ///< from the state before start, one sample per change
  /// False when the drone's final state is not known (a distributed run lost contact with
  /// it, or its DEX died): `state` is then only what was last seen.
  bool final = true;
};

struct RunResult {
  bool completed = false;
  double duration = 0.0;              ///< mission seconds
  std::optional<Failure> failure;     ///< set when the mission failed
  std::string error;                  ///< human summary of the failure
  std::vector<DroneSummary> drones;
  std::uint64_t activations = 0;      ///< node activations over all drones
  /// In process: drones that deliveries of sync-point arrivals to drone sets looked at, summed;
  /// with messages traced, (k - 1) per arrival at a fleet-wide barrier; without, about one.
  std::uint64_t set_delivery_steps = 0;
  /// Distributed runs: how late the messages between drones were (in process they take no time).
  std::optional<MessageLatency> latency;
  /// In process on real time: the most mission seconds an event ran late (mid::EventLoop::max_lag).
  double max_lag = 0.0;
};

/// What a run says of itself beyond its outcome, in the words `eamos run` prints after
/// "warning: " and the Python module gives as RuntimeWarnings: for a completed mission, each
/// drone it leaves in the air or armed (whose final state is known); on real time, how far
/// the run fell behind `pace` (the speed as the caller names it: "--speed 5", "speed=5") when
/// an event ran more than a tenth of a mission second late, since work that takes no mission
/// time then runs at the wall's mission time and the run's timing strays from the plan's.
std::vector<std::string> run_warnings(const RunResult& r, const std::string& pace);

/// The event a trace ends with: `mission`, outcome `completed` or `failed` (reason: the
/// error), at the mission time the mission ended (RunResult::duration). Every runner, in
/// process or distributed, writes it last.
TraceEvent mission_end_event(const RunResult& r);

/// The trace event of message `m` arriving at drone `to` (whose mission is `receiver`) at
/// mission time `received`: its kind, both drones, the node and, for a cloned sync point,
/// the instance (the sender, which holds that clone).
TraceEvent message_event(const Mission& receiver, const Message& m, int to, double received);

/// Writes each drone's telemetry to a trace at a fixed rate of mission time. A sample is
/// written when anything in it changed since that drone's last one, so a fleet standing on
/// the ground costs nothing and a hung mission does not fill the disk.
class TelemetryRecorder {
 public:
  TelemetryRecorder(TraceSink* trace, double hz) : trace_(trace), hz_(hz) {}
  bool enabled() const { return trace_ && hz_ > 0; }
  double period() const { return 1.0 / hz_; }
  /// The state of drone `name` at mission time `t` (t on the rate's grid, or, from a
  /// sampled stream, the sample's own time).
  void sample(const std::string& name, const mid::DroneState& s, double t);
  /// For a stream of states (the ground's DDS telemetry): true when `t` reached the
  /// drone's next slot of the rate, which it then moves on.
  bool due(const std::string& name, double t);

 private:
  TraceSink* trace_;
  double hz_;
  std::map<std::string, mid::DroneState> last_;
  std::map<std::string, double> next_;
};

/// Runs `missions` (one per drone, same hash, index order = fleet order). Setup problems
/// (unknown adapter, mismatched hashes) come back as a failed result before anything runs.
RunResult run_in_process(const std::vector<Mission>& missions, const mid::AdapterRegistry& adapters,
                         TraceSink* trace, const RunOptions& options = {});

}  // namespace eamos::dex
