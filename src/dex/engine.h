#pragma once
// The DEX's execution engine for one drone (paper, section V): it runs the drone's MDG
// event-driven on the event loop — a node starts when all its prerequisites have ended,
// nothing polls, no thread per node. Control structures are condition nodes that choose
// which successors to trigger; the engine keeps its run state apart from the Mission,
// which it never changes (Taskflow: graph and executor apart).
#include <deque>
#include <map>
#include <optional>
#include <functional>
#include <string>
#include <vector>

#include "dex/bridge.h"
#include "dex/failure.h"
#include "dex/mission.h"
#include "dex/observer.h"
#include "dex/trace.h"
#include "mid/drone_api.h"
#include "mid/event_loop.h"

namespace eamos::dex {

/// A uniform property (X, Y, Z, Battery, Armed, Landed, SensorK) of a drone state;
/// booleans as 0/1, an unknown sensor as 0.
double property_of(const mid::DroneState& s, const std::string& name);

struct EngineHooks {
  Transport* transport = nullptr;  ///< OutBridge's way out
  TraceSink* trace = nullptr;
  std::function<void(const Failure&)> on_failure;
  std::function<void()> on_end;  ///< the mission's end node ran (this drone is the lead)
  /// The engine has just settled (handled an event completely) with nothing active: the
  /// moment a runner checks whether the mission is complete.
  std::function<void()> on_idle;
  /// `eamos verify` only: sees action starts and may decide conditions (dex/observer.h).
  RunObserver* observer = nullptr;
  /// Kept true while a condition of this engine watches properties, false otherwise: a
  /// runner of many engines reads it before calling properties_changed, whose first look
  /// at a cold engine costs a cache miss per motion step of its drone.
  bool* watching = nullptr;
};

/// Iterations in a row a Repeat may run without mission time passing before the engine
/// calls it a loop that makes no progress and fails the mission (its failsafe runs).
inline constexpr int kMaxInstantIterations = 10000;

class Engine {
 public:
  Engine(const Mission& mission, mid::Drone& drone, mid::EventLoop& loop, EngineHooks hooks);
  ~Engine();
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  /// Starts the drone's init clone, if it holds one (mission start).
  void start();
  /// InBridge: a message from another drone.
  void receive(const Message& m);
  /// InBridge: another drone's arrival at this drone's sync-point clone `node` (its index
  /// in the Mission), found by a transport that delivers many: receive() finds it itself.
  /// The caller has checked the mission hash.
  void receive_arrival(int node, const Message& m);
  /// receive_arrival for a transport that settles the run itself after delivering to a whole
  /// set (the in-process one): an arrival that leaves the barrier waiting only counts, with
  /// no queue, drain or on_idle. A fleet-wide barrier delivers k - 1 of them per arrival.
  void count_arrival(int node, const Message& m);
  /// `n` more arrivals at sync-point clone `node` (outside every Repeat/Do body), counted by
  /// a transport that tells them in one go: the barrier is not passed here, the next
  /// arrival or this drone's own does it. Returns the arrivals still missing.
  int add_arrivals(int node, int n);
  /// InBridge: another drone's telemetry; re-evaluates the conditions that read it.
  void receive(std::shared_ptr<const Telemetry> t);
  /// A property of `drone` changed: re-evaluate the conditions that wait on it.
  void properties_changed(int drone);
  /// The mission failed elsewhere or here: start nothing more, cancel what runs.
  void halt();

  /// Actions, timers or watched conditions still active on this drone.
  bool busy() const { return active_ > 0; }
  std::uint64_t activations() const { return activations_; }
  /// Reads a property of any drone: own values from the drone, others' from telemetry.
  double property(int drone, const std::string& name) const;

 private:
  /// One running activation of an action or PauseFor node. A node started again while
  /// an earlier activation still runs (async work in a loop) has several; each ends once.
  struct Instance {
    std::uint64_t id = 0;
    mid::ActionId action = mid::kNoAction;
    mid::TimerId timer = mid::kNoTimer;
  };
  struct State {
    int exec_pending = 0;
    int back_pending = 0;
    std::vector<Instance> running;
    /// Watched conditions: activations waiting on the condition (Wait*/Pause* started
    /// again while waiting wait together; a Do has at most one run).
    int watchers = 0;
    /// Repeat conditions: the next iteration, waiting for its turn on the event loop.
    mid::TimerId next_iteration = mid::kNoTimer;
    double iteration_started = 0.0;  ///< mission time the current iteration began
    int instant_iterations = 0;      ///< iterations in a row that took no mission time
    long long iterations = 0;
    int last_value = -1;  ///< watched conditions: last traced value (-1 none), to log changes only
    long long epoch = 0;  ///< run of the node's body (Mission::Node::scope) its counters belong to
    /// Sync-point clones: this drone's own arcs into it have all fired (or it has none),
    /// and the other drones' arrivals still to come.
    bool local_ready = false;
    int arrivals_pending = 0;
  };
  struct Delivery {
    int node;
    graph::ArcKind kind;
    bool from_terminal;    ///< a partner release sent by a terminal (not by a condition)
    bool arrival = false;  ///< another drone arrived at this sync point (not an arc)
  };

  void deliver(int node, graph::ArcKind kind, bool from_terminal);
  void drain();
  void activate(int node, bool by_back_arc);
  void activate_action(int node);
  void activate_pause(int node);
  void activate_repeat(int node, bool by_back_arc);
  void schedule_iteration(int node);
  bool take_instance(int node, std::uint64_t id);
  void arrive(int node);
  void pass_barrier_when_complete(int node);
  void announce(int node);
  bool current(const Message& m);
  void reset_counters(int node);
  void activate_condition(int node, bool by_back_arc);
  /// `released`: a partner arc released it (it ends without its branch having run).
  void end(int node, graph::Branch branch, bool released_by_partner = false, bool released = false);
  /// The trace's "node" event of a node that is not an action (docs/trace.md).
  void trace_node(const Node& n, const char* outcome, graph::Branch branch);
  void evaluate_watch(int node);
  void cancel_local(const std::vector<int>& nodes);
  void stop_watching(int node);
  void on_action_end(int node, std::uint64_t instance, const mid::ActionEnd& e);
  void trace_end(const Node& n, const mid::ActionEnd& e);
  bool condition_value(int node);
  void trace(const Node& n, const std::string& event, const std::string& outcome = "");

  const Mission& m_;
  mid::Drone& drone_;
  mid::EventLoop& loop_;
  EngineHooks hooks_;
  std::vector<State> state_;
  std::deque<Delivery> queue_;
  bool draining_ = false;
  bool halted_ = false;
  int active_ = 0;
  std::uint64_t next_instance_ = 0;
  std::uint64_t activations_ = 0;
  std::vector<int> watched_;  ///< condition nodes currently watching (through watch and unwatch)
  void watch(int node);
  void unwatch(int node);
  void unwatch_all();
  /// The newest telemetry of each drone this one reads (Mission::reads, in board_drones_'s
  /// order): sized by what the mission reads, not by the fleet, which at 10,000 drones would
  /// be 10⁸ pointers over one process.
  std::vector<std::shared_ptr<const Telemetry>> board_;
  std::vector<int> board_drones_;  ///< sorted
  /// board_'s slot for `drone`, or -1 when this drone does not read it.
  int board_slot(int drone) const;
  /// Runs of each Repeat/Do body (by the condition's MEG id) this drone knows of: a body's
  /// nodes reset their counters when a new run reaches them, and messages from an older
  /// run are dropped. This is what keeps a cancelled do-branch or a finished iteration from
  /// leaking a late trigger into the next run.
  std::map<int, long long> epoch_;
  void refresh(int node);
  long long epoch_of(int scope) const;

  // The Do family (engine_do.cpp): a Do condition runs its do-branch at most once at a time
  // and watches its condition while the run goes on.
  /// Starts a run of the do-branch (cancelling one still going) or skips it.
  void activate_do(int node);
  /// The condition of a running Do may have changed: flips it when it no longer says "do".
  void recheck_do(int node);
  /// Ends the run (its watch and, on every drone, its do-branch) and starts the done-branch.
  void flip_do(int node);
  /// Cancels the running do-branch of `node` on every drone; a new epoch makes its late
  /// messages stale.
  void cancel_do_run(int node);
};

}  // namespace eamos::dex
