#pragma once
// The DEX process's state (src/launch/dex_process.h is its interface): split over
// dex_process.cpp (set-up, the start barrier, receiving) and dex_run.cpp (status, the
// end of the mission, abandoning it).
#include <condition_variable>
#include <csignal>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "dex/engine.h"
#include "dex/failsafe.h"
#include "dex/mission.h"
#include "dex/separation.h"
#include "dex/trace_writers.h"
#include "launch/dex_process.h"
#include "launch/termination.h"
#include "launch/inbox.h"
#include "transport/dds_transport.h"

namespace eamos::launch {

using transport::LifecycleKind;
using transport::LifecycleSample;
using transport::Phase;
using transport::StatusSample;
using transport::TelemetrySample;
using transport::TraceSample;
using transport::TriggerSample;

/// Writes each trace event of this drone to the ground's merged trace. A DDS write may
/// block (a quarter of the lease), so events are queued and written after the running
/// callback: the event that reports a failed action must not hold up the failsafe and the
/// ABORT it leads to (docs/faults.md).
class DdsTraceSink : public dex::TraceSink {
 public:
  DdsTraceSink(transport::DdsNode& node, mid::EventLoop& loop, std::string hash, std::uint64_t run, int drone)
      : node_(node), loop_(loop), hash_(std::move(hash)), run_(run), drone_(drone) {}
  void record(const dex::TraceEvent& e) override {
    queued_.push_back(TraceSample{hash_, run_, drone_, ++seq_, e});
    if (scheduled_) return;
    scheduled_ = true;
    loop_.after(0.0, [this] { flush(); });
  }
  /// Writes what is queued; also called once the loop has stopped.
  void flush() {
    scheduled_ = false;
    std::vector<TraceSample> out;
    out.swap(queued_);
    for (const TraceSample& s : out) node_.write(s);
  }

 private:
  transport::DdsNode& node_;
  mid::EventLoop& loop_;
  std::string hash_;
  std::uint64_t run_;
  int drone_;
  std::uint64_t seq_ = 0;
  std::vector<TraceSample> queued_;
  bool scheduled_ = false;
};

/// How many distinct ignored inputs (faults, other runs, other missions) a DEX remembers
/// having logged; beyond that it stops logging them rather than grow.
inline constexpr std::size_t kMaxRemembered = 1000;

/// Set by the DEX's handler of the stop signals (dex_process.cpp); 0 until one came.
extern volatile std::sig_atomic_t g_dex_signal;

class DexProcess {
 public:
  DexProcess(const DexProcessOptions& o, std::ostream& out, std::ostream& err) : o_(o), out_(out), err_(err) {}
  int run(const mid::AdapterRegistry& adapters);

 private:
  // --- before the start (main thread) ---
  bool load(const mid::AdapterRegistry& adapters);
  bool open_dds();
  bool wait_for_start();
  /// Writes READY when every other drone has been heard from; whether it did.
  bool ready_when_all_seen();
  void publish_heard();
  /// Gives up waiting for the other drones (DexProcessOptions::unready_limit_s); false.
  bool leave_unready();
  /// The drones not heard from yet that this DEX's ready timeout waits for (all but itself
  /// and DexProcessOptions::later_drones), by name.
  std::vector<std::string> unheard_earlier();
  /// Checks DexProcessOptions::later_drones against the fleet; false with a message.
  bool check_later_drones();
  /// A START seen while waiting: true when it starts this process's run, false when this
  /// process must give up, nothing when it is not this process's (noted in `refused`).
  std::optional<bool> take_start(const LifecycleSample& s, std::set<std::uint64_t>& refused);
  void on_lifecycle_waiting(const LifecycleSample& s);
  /// Notes (DDS thread) a status of this drone from another process in a run: another DEX
  /// flies this drone, and a START naming this process must be refused.
  void on_status_waiting(const StatusSample& s);
  /// "" or why this process must not start (another DEX flies its drone); wait_mutex_.
  std::string flown_elsewhere();
  /// Answers `start` (which names this process) with REFUSED, saying `why`.
  void refuse(const LifecycleSample& start, const std::string& why);
  // --- the mission (loop thread) ---
  bool begin();
  /// Waits until the start instant; false when the run was refused or aborted meanwhile.
  bool reach_start_instant();
  void open_traces();
  void make_engine();
  /// The run's own faults: a stalled loop, the time limit.
  void watch_run();
  void on_trigger(const TriggerSample& s);
  /// True when `event` (a trigger or cancel that arrived) came later than
  /// --max-trigger-latency: the mission is then abandoned and the message not obeyed.
  bool too_late(const dex::TraceEvent& event);
  void on_telemetry(const TelemetrySample& s);
  void start_separation();
  /// Publishes this drone's newest state now or, within a period of the last one
  /// (DexProcessOptions::state_rate_hz), at the period's end.
  void publish_state(const mid::DroneState& s);
  void send_state(const mid::DroneState& s);
  void seed_telemetry(const TelemetrySample& s);
  void on_lifecycle(const LifecycleSample& s);
  /// A START of another run: refused when it names this process (it runs one already).
  void on_other_start(const LifecycleSample& s);
  void on_status(const StatusSample& s);
  void on_lost(const std::string& hash, int drone, std::uint64_t nonce);
  // --- checks of what arrives, even from an authenticated peer (dex_checks.cpp) ---
  bool trigger_allowed(const TriggerSample& s, std::string& why) const;
  /// An arrival broadcast at a sync point whose clone here waits for its sender.
  bool waits_for_arrival(const dex::Message& m) const;
  bool abort_allowed(const LifecycleSample& s, std::string& why) const;
  bool finish_agreed(int lead, std::string& why) const;
  void on_finished(const LifecycleSample& s);
  void check_pending_finished();
  /// Logs once per sender and kind of fault that a sample was ignored.
  void reject(int sender, const std::string& what, const std::string& why);
  std::string who(int drone) const;
  void heartbeat();
  /// Publishes what changed (busy/idle, counters), lets the lead look for the mission's
  /// end and checks a pending FINISHED: after every input and every trigger sent.
  void settle();
  void schedule_settle();
  void publish_status(bool force = false);
  /// True when a change of counters alone waits for the end of its gap (counters_gap_for),
  /// where a timer publishes the newest status.
  bool defer_counters();
  void check_finished();
  /// Trigger counters of the whole fleet (this drone's own and every other drone's newest
  /// status), and the latest instant another drone went idle.
  struct FleetCounters {
    std::uint64_t sent = 0;
    std::uint64_t received = 0;
    double others_idle_since = 0.0;
  };
  /// False with `why` when another drone has no status yet or is busy (with `running_only`,
  /// also when it has left the running phase); otherwise fills `c`.
  bool others_idle(bool running_only, FleetCounters& c, std::string& why) const;
  void complete();
  void abandon(const std::string& reason, const std::optional<dex::Failure>& failure, bool broadcast);
  /// Every failsafe of this drone's abandoned mission is over (dex::FailsafeWait).
  void on_failsafe_over();
  void on_internal_error(const std::string& what);
  /// The loop found itself `stalled_s` wall seconds behind (EventLoop::on_stall).
  void on_stall(double stalled_s);
  void finish_loop();
  bool ours(const std::string& hash, std::uint64_t run);
  void note_foreign(const std::string& hash);
  StatusSample status_now(Phase phase) const;
  std::string name() const { return mission_.fleet[mission_.self]; }
  /// Wall seconds between heartbeats: a quarter of the lease, so one late heartbeat does
  /// not cost the drone its liveliness. Also how soon a signal is noticed.
  double heartbeat_s() const { return o_.dds.lease_s / 4; }

  const DexProcessOptions& o_;
  std::ostream& out_;
  std::ostream& err_;
  dex::Mission mission_;
  std::uint64_t nonce_ = 0;  // this process, in READY; set in run()
  std::unique_ptr<mid::EventLoop> loop_;
  std::unique_ptr<mid::Drone> drone_;
  Inbox inbox_;

  // Shared with DDS threads until the start.
  std::mutex wait_mutex_;
  std::condition_variable wait_cv_;
  std::vector<LifecycleSample> starts_;
  std::map<std::uint64_t, std::string> aborts_;  ///< run id → reason, of ABORTs seen (0: the ground's barrier)
  std::string flown_elsewhere_;                  ///< see on_status_waiting

  // The run (loop thread only).
  LifecycleSample start_;
  std::unique_ptr<transport::DdsTransport> transport_;
  std::unique_ptr<DdsTraceSink> dds_trace_;
  std::ofstream trace_file_;
  std::unique_ptr<dex::JsonlTrace> jsonl_;
  std::unique_ptr<dex::LiveLog> live_;
  dex::TeeTrace tee_;
  std::unique_ptr<dex::Engine> engine_;
  std::unique_ptr<dex::SeparationGuard> separation_;  ///< give-ways of this drone (dex/separation.h)
  Phase phase_ = Phase::waiting;
  bool end_reached_ = false;
  std::uint64_t received_ = 0;
  std::map<int, StatusSample> statuses_;  ///< other drones' newest status of this run
  std::optional<StatusSample> last_status_;
  double status_published_at_ = -1e300;  ///< wall time of last_status_
  bool counters_due_ = false;            ///< a timer publishes the newest counters
  bool settle_scheduled_ = false;
  std::optional<TerminationDetector> termination_;  ///< the lead's waves (made at the start)
  std::uint64_t wave_answered_ = 0;                 ///< the newest wave this drone answered
  std::string error_;
  std::set<std::string> foreign_;
  std::set<std::uint64_t> stale_runs_;
  std::unique_ptr<dex::FailsafeWait> failsafe_wait_;  ///< from the abandon on
  /// Per sender, the sequence number of the newest accepted trigger. Reliable DDS hands one
  /// writer's samples over in order (also what a re-matched writer sends again from its
  /// durable history), so a number not above it is a repeat: one number per drone, however
  /// long the mission.
  std::vector<std::uint64_t> last_trigger_seq_;
  std::set<std::string> rejected_;                        ///< what was logged as ignored
  std::optional<LifecycleSample> pending_finished_;       ///< a FINISHED this DEX does not agree with (yet)
  double joined_at_ = 0.0;  ///< wall time the DDS participant was created
  int heard_published_ = 0;            ///< other drones heard from, as last published (status)
  double heard_published_at_ = -1e300;  ///< wall time of that status
  double state_period_s = 0.0;                 ///< mission seconds between published states; 0: every change
  double state_published_at_ = -1e300;         ///< mission time of the last published state
  std::optional<mid::DroneState> state_due_;   ///< newest state not yet published; a timer is set for it
  double pending_since_ = 0.0;                            ///< wall time it came

  // Last, so it goes first: its listener threads use everything above.
  std::unique_ptr<transport::DdsNode> node_;
};

}  // namespace eamos::launch
