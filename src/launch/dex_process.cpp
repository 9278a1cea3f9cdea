#include "dex/trace_writers.h"
#include "launch/dex_process.h"

#include <chrono>
#include <condition_variable>
#include <fstream>
#include <iostream>
#include <optional>
#include <random>
#include <set>
#include <thread>

#include "dex/engine.h"
#include "dex/runner.h"
#include "dex/mission.h"
#include "launch/inbox.h"
#include "launch/wall_time.h"
#include "transport/dds_transport.h"

namespace eamos::launch {

namespace {

using transport::LifecycleKind;
using transport::LifecycleSample;
using transport::Phase;
using transport::StatusSample;
using transport::TelemetrySample;
using transport::TraceSample;
using transport::TriggerSample;

std::uint64_t process_nonce() {
  std::random_device rd;
  std::uint64_t n = (static_cast<std::uint64_t>(rd()) << 32) ^ rd() ^ static_cast<std::uint64_t>(unix_ns());
  return n == 0 ? 1 : n;
}

/// Writes each trace event of this drone to the ground's merged trace.
class DdsTraceSink : public dex::TraceSink {
 public:
  DdsTraceSink(transport::DdsNode& node, std::string hash, std::uint64_t run, int drone)
      : node_(node), hash_(std::move(hash)), run_(run), drone_(drone) {}
  void record(const dex::TraceEvent& e) override { node_.write(TraceSample{hash_, run_, drone_, ++seq_, e}); }

 private:
  transport::DdsNode& node_;
  std::string hash_;
  std::uint64_t run_;
  int drone_;
  std::uint64_t seq_ = 0;
};

class DexProcess {
 public:
  DexProcess(const DexProcessOptions& o, std::ostream& out, std::ostream& err) : o_(o), out_(out), err_(err) {}
  int run(const mid::AdapterRegistry& adapters);

 private:
  // --- before the start (main thread) ---
  bool wait_for_start();
  void on_lifecycle_waiting(const LifecycleSample& s);
  // --- the mission (loop thread) ---
  void begin();
  void on_trigger(const TriggerSample& s);
  void on_telemetry(const TelemetrySample& s);
  void on_lifecycle(const LifecycleSample& s);
  void on_status(const StatusSample& s);
  void on_lost(const std::string& hash, int drone);
  void tick();
  void publish_status(bool force = false);
  void check_finished();
  void complete();
  void abandon(const std::string& reason, const std::optional<dex::Failure>& failure, bool broadcast);
  void wait_for_failsafe();
  void finish_loop();
  bool ours(const std::string& hash, std::uint64_t run);
  void note_foreign(const std::string& hash);
  StatusSample status_now(Phase phase) const;
  std::string name() const { return mission_.fleet[mission_.self]; }
  /// Wall seconds between ticks: how soon busy/idle changes are published.
  double tick_s() const { return std::min(0.02, o_.dds.lease_s / 4); }

  const DexProcessOptions& o_;
  std::ostream& out_;
  std::ostream& err_;
  dex::Mission mission_;
  std::uint64_t nonce_ = process_nonce();
  std::unique_ptr<mid::EventLoop> loop_;
  std::unique_ptr<mid::Drone> drone_;
  std::unique_ptr<transport::DdsNode> node_;
  Inbox inbox_;

  // Shared with DDS threads until the start.
  std::mutex wait_mutex_;
  std::condition_variable wait_cv_;
  std::vector<LifecycleSample> starts_;

  // The run (loop thread only).
  LifecycleSample start_;
  std::unique_ptr<transport::DdsTransport> transport_;
  std::unique_ptr<DdsTraceSink> dds_trace_;
  std::ofstream trace_file_;
  std::unique_ptr<dex::JsonlTrace> jsonl_;
  std::unique_ptr<dex::LiveLog> live_;
  dex::TeeTrace tee_;
  std::unique_ptr<dex::Engine> engine_;
  Phase phase_ = Phase::waiting;
  bool end_reached_ = false;
  std::uint64_t received_ = 0;
  std::map<int, StatusSample> statuses_;  ///< other drones' newest status of this run
  std::uint64_t status_changes_ = 0;
  std::optional<StatusSample> last_status_;
  int quiet_ticks_ = 0;
  std::tuple<std::uint64_t, std::uint64_t, std::uint64_t> quiet_signature_{};
  std::string error_;
  std::set<std::string> foreign_;
  std::set<std::uint64_t> stale_runs_;
  double failsafe_since_ = 0.0;
};

int DexProcess::run(const mid::AdapterRegistry& adapters) {
  std::string error;
  std::string file = o_.folder + "/mission.json";
  if (!dex::load_mission_file(file, mission_, error)) {
    err_ << "eamos dex: error: " << error << "\n";
    return 1;
  }
  mid::ClockOptions clock;
  clock.mode = mid::ClockMode::real_time;
  clock.speed = o_.speed;
  loop_ = std::make_unique<mid::EventLoop>(clock);
  mid::CreateResult made = adapters.create(mission_.settings.adapter, mission_.settings, mission_.type, *loop_);
  if (made.status != mid::CreateStatus::success) {
    err_ << "eamos dex: error: " << name() << ": " << made.message << "\n";
    return 1;
  }
  drone_ = std::move(made.drone);

  transport::DdsHandlers h;
  h.trigger = [this](TriggerSample s) { inbox_.deliver([this, s = std::move(s)] { on_trigger(s); }); };
  h.telemetry = [this](TelemetrySample s) {
    inbox_.deliver_telemetry(s, [this, s] { on_telemetry(s); });
    wait_cv_.notify_all();
  };
  h.lifecycle = [this](LifecycleSample s) {
    on_lifecycle_waiting(s);
    inbox_.deliver([this, s = std::move(s)] { on_lifecycle(s); });
  };
  h.status = [this](StatusSample s) { inbox_.deliver([this, s = std::move(s)] { on_status(s); }); };
  h.lost = [this](const std::string& hash, int drone) { inbox_.deliver([this, hash, drone] { on_lost(hash, drone); }); };
  node_ = transport::DdsNode::open(o_.dds, std::move(h), error);
  if (!node_) {
    err_ << "eamos dex: error: " << error << "\n";
    return 1;
  }
  if (!wait_for_start()) return 1;
  begin();
  loop_->run_until(o_.time_limit_s + 1000.0);
  node_->flush(1.0);
  if (phase_ == Phase::completed) {
    out_ << name() << ": mission completed\n";
    return 0;
  }
  err_ << "eamos dex: " << name() << ": mission failed: " << error_ << "\n";
  return 1;
}

void DexProcess::on_lifecycle_waiting(const LifecycleSample& s) {
  if (s.kind != LifecycleKind::start || s.mission_hash != mission_.hash) return;
  std::lock_guard<std::mutex> lock(wait_mutex_);
  starts_.push_back(s);
  wait_cv_.notify_all();
}

bool DexProcess::wait_for_start() {
  node_->write(TelemetrySample{0, dex::Telemetry{mission_.hash, mission_.self, drone_->state()}});
  publish_status(true);
  const double lease = o_.dds.lease_s;
  const double deadline = o_.start_timeout_s > 0 ? wall_s() + o_.start_timeout_s : 1e300;
  bool ready_sent = false;
  std::set<std::uint64_t> refused;
  out_ << name() << ": DEX of mission " << mission_.hash.substr(0, 12) << " waiting for its peers\n" << std::flush;
  for (;;) {
    node_->assert_alive();
    std::vector<LifecycleSample> starts;
    {
      std::unique_lock<std::mutex> lock(wait_mutex_);
      wait_cv_.wait_for(lock, std::chrono::duration<double>(lease / 4));
      starts.swap(starts_);
    }
    if (!ready_sent) {
      std::map<int, TelemetrySample> seen = inbox_.latest();
      bool all = true;
      for (int d : mission_.reads)
        if (d != mission_.self && !seen.count(d)) all = false;
      if (all) {
        LifecycleSample ready;
        ready.mission_hash = mission_.hash;
        ready.drone = mission_.self;
        ready.kind = LifecycleKind::ready;
        ready.nonce = nonce_;
        node_->write(ready);
        ready_sent = true;
        out_ << name() << ": ready\n" << std::flush;
      }
    }
    for (const LifecycleSample& s : starts) {
      bool mine = s.drone == transport::kGround && static_cast<int>(s.nonces.size()) > mission_.self &&
                  s.nonces[mission_.self] == nonce_;
      if (mine) {
        if (s.speed != o_.speed) {
          err_ << "eamos dex: error: " << name() << ": the ground started run " << s.run_id << " at speed "
               << s.speed << ", this DEX runs at " << o_.speed << "; start it with --speed " << s.speed << "\n";
          LifecycleSample abort{mission_.hash, mission_.self, LifecycleKind::abort, s.run_id};
          abort.reason = name() + " runs at another speed than the ground";
          node_->write(abort);
          node_->flush(1.0);
          return false;
        }
        start_ = s;
        return true;
      }
      // A start that names another process for this drone: the run began (or was
      // abandoned) without this process. A restarted DEX never joins a run in progress.
      if (refused.insert(s.run_id).second)
        err_ << name() << ": not joining run " << s.run_id
             << ": it was started with another process for this drone (this DEX was restarted?)\n";
    }
    if (wall_s() > deadline) {
      err_ << "eamos dex: error: " << name() << ": no start within " << o_.start_timeout_s
           << " s; is `eamos launch` running on domain " << o_.dds.domain << "?\n";
      return false;
    }
  }
}

void DexProcess::begin() {
  // Mission time 0 is the start instant the ground chose, the same on every drone.
  double lease = o_.dds.lease_s;
  while (unix_ns() < start_.start_at_ns) {
    node_->assert_alive();
    double left = (start_.start_at_ns - unix_ns()) / 1e9;
    std::this_thread::sleep_for(std::chrono::duration<double>(std::min(left, lease / 4)));
  }
  transport_ = std::make_unique<transport::DdsTransport>(*node_, start_.run_id);
  dds_trace_ = std::make_unique<DdsTraceSink>(*node_, mission_.hash, start_.run_id, mission_.self);
  tee_.add(dds_trace_.get());
  if (o_.log) {
    live_ = std::make_unique<dex::LiveLog>(out_);
    tee_.add(live_.get());
  }
  if (!o_.trace_file.empty()) {
    trace_file_.open(o_.trace_file, std::ios::trunc);
    if (trace_file_) {
      jsonl_ = std::make_unique<dex::JsonlTrace>(trace_file_);
      tee_.add(jsonl_.get());
    } else {
      err_ << name() << ": cannot write trace '" << o_.trace_file << "'\n";
    }
  }
  dex::EngineHooks hooks;
  hooks.transport = transport_.get();
  hooks.trace = &tee_;
  hooks.on_failure = [this](const dex::Failure& f) {
    abandon(f.drone + "." + f.action + " (line " + std::to_string(f.line) + ") failed: " + f.reason, f, true);
  };
  hooks.on_end = [this] {
    end_reached_ = true;
    publish_status();
  };
  engine_ = std::make_unique<dex::Engine>(mission_, *drone_, *loop_, hooks);
  phase_ = Phase::running;
  inbox_.attach(*loop_, [this](const TelemetrySample& s) { on_telemetry(s); });
  drone_->subscribe([this](const mid::DroneState& s) {
    engine_->properties_changed(mission_.self);
    transport_->publish(std::make_shared<const dex::Telemetry>(dex::Telemetry{mission_.hash, mission_.self, s}));
  });
  loop_->at(o_.time_limit_s, [this] {
    if (phase_ != Phase::running) return;
    abandon("mission did not complete within " + std::to_string(o_.time_limit_s) +
                " s of mission time; raise --time-limit if it is meant to run longer",
            std::nullopt, true);
  });
  publish_status(true);
  engine_->start();
  tick();
}

void DexProcess::tick() {
  // A heartbeat of the loop itself: liveliness is asserted only while the loop runs, so a
  // hung DEX is lost like a dead one; status changes (busy/idle) are published here.
  node_->assert_alive();
  publish_status();
  check_finished();
  double every = tick_s() * o_.speed;
  loop_->after(every, [this] { tick(); });
}

bool DexProcess::ours(const std::string& hash, std::uint64_t run) {
  if (hash != mission_.hash) {
    note_foreign(hash);
    return false;
  }
  if (run != start_.run_id) {
    if (stale_runs_.insert(run).second)
      err_ << name() << ": ignoring messages of run " << run << " (this drone is in run " << start_.run_id << ")\n";
    return false;
  }
  return true;
}

void DexProcess::note_foreign(const std::string& hash) {
  if (foreign_.insert(hash).second)
    err_ << name() << ": ignoring messages of another mission (hash " << hash.substr(0, 12)
         << "…) on DDS domain " << o_.dds.domain << "\n";
}

void DexProcess::on_trigger(const TriggerSample& s) {
  if (!ours(s.message.mission_hash, s.run_id) || s.to != mission_.self) return;
  ++received_;
  if (phase_ == Phase::running) engine_->receive(s.message);
  publish_status();
}

void DexProcess::on_telemetry(const TelemetrySample& s) {
  if (s.telemetry.mission_hash != mission_.hash) return note_foreign(s.telemetry.mission_hash);
  if (s.telemetry.from == mission_.self) return;
  // Telemetry of run 0 is what a drone publishes before any start: its initial state.
  if (s.run_id != 0 && s.run_id != start_.run_id) return;
  engine_->receive(std::make_shared<const dex::Telemetry>(s.telemetry));
}

void DexProcess::on_lifecycle(const LifecycleSample& s) {
  if (s.kind == LifecycleKind::ready || s.kind == LifecycleKind::start) return;
  if (!ours(s.mission_hash, s.run_id)) return;
  if (s.kind == LifecycleKind::abort) {
    std::string who = s.drone == transport::kGround ? "the ground" : mission_.fleet.at(s.drone);
    abandon("aborted by " + who + ": " + s.reason, s.failure, false);
  } else if (s.kind == LifecycleKind::finished && phase_ == Phase::running) {
    complete();
  }
}

void DexProcess::on_status(const StatusSample& s) {
  if (s.mission_hash != mission_.hash) return note_foreign(s.mission_hash);
  if (s.run_id != start_.run_id || s.drone == mission_.self) return;
  statuses_[s.drone] = s;
  ++status_changes_;
}

void DexProcess::on_lost(const std::string& hash, int drone) {
  if (hash != mission_.hash || drone == mission_.self || phase_ != Phase::running) return;
  auto it = statuses_.find(drone);
  if (it != statuses_.end() && (it->second.phase == Phase::completed || it->second.phase == Phase::failed))
    return;  // it finished and left: not lost
  std::string lost = drone >= 0 && drone < static_cast<int>(mission_.fleet.size()) ? mission_.fleet[drone] : "?";
  char lease[32];
  std::snprintf(lease, sizeof lease, "%g", o_.dds.lease_s);
  abandon(lost + " lost: no liveliness for " + lease + " s (its DEX stopped, hung or is unreachable)",
          std::nullopt, true);
}

StatusSample DexProcess::status_now(Phase phase) const {
  StatusSample s;
  s.mission_hash = mission_.hash;
  s.drone = mission_.self;
  s.run_id = start_.run_id;
  s.phase = phase;
  s.busy = engine_ && engine_->busy();
  s.end_reached = end_reached_;
  s.sent = transport_ ? transport_->sent() : 0;
  s.received = received_;
  s.activations = engine_ ? engine_->activations() : 0;
  s.since = last_status_ && last_status_->busy == s.busy ? last_status_->since : (loop_ ? loop_->now() : 0.0);
  s.state = drone_->state();
  return s;
}

void DexProcess::publish_status(bool force) {
  StatusSample s = status_now(phase_);
  if (!force && last_status_ && last_status_->phase == s.phase && last_status_->busy == s.busy &&
      last_status_->end_reached == s.end_reached && last_status_->sent == s.sent &&
      last_status_->received == s.received)
    return;
  node_->write(s);
  last_status_ = s;
}

void DexProcess::check_finished() {
  // Only the lead (it ran the end node) decides; everyone else follows its FINISHED.
  if (phase_ != Phase::running || !end_reached_ || engine_->busy()) {
    quiet_ticks_ = 0;
    return;
  }
  std::uint64_t sent = transport_->sent(), received = received_;
  double idle_since = last_status_ ? last_status_->since : loop_->now();
  for (int d = 0; d < static_cast<int>(mission_.fleet.size()); ++d) {
    if (d == mission_.self) continue;
    auto it = statuses_.find(d);
    if (it == statuses_.end() || it->second.busy || it->second.phase != Phase::running) {
      quiet_ticks_ = 0;
      return;
    }
    sent += it->second.sent;
    received += it->second.received;
    idle_since = std::max(idle_since, it->second.since);
  }
  auto signature = std::make_tuple(sent, received, status_changes_);
  if (sent != received || (quiet_ticks_ > 0 && signature != quiet_signature_)) {
    quiet_ticks_ = 0;
    return;
  }
  quiet_signature_ = signature;
  ++quiet_ticks_;
  if (quiet_ticks_ * tick_s() < o_.settle_s) return;
  LifecycleSample finished{mission_.hash, mission_.self, LifecycleKind::finished, start_.run_id};
  // The mission ended when its last drone went idle, not when the lead noticed.
  finished.t = idle_since;
  node_->write(finished);
  complete();
}

void DexProcess::complete() {
  phase_ = Phase::completed;
  publish_status(true);
  loop_->stop();
}

void DexProcess::abandon(const std::string& reason, const std::optional<dex::Failure>& failure, bool broadcast) {
  if (phase_ != Phase::running) return;
  phase_ = Phase::failed;
  error_ = reason;
  err_ << name() << ": " << reason << "\n";
  if (broadcast) {
    LifecycleSample abort{mission_.hash, mission_.self, LifecycleKind::abort, start_.run_id};
    abort.reason = reason;
    abort.failure = failure;
    abort.t = loop_->now();
    node_->write(abort);
  }
  engine_->halt();
  mid::DroneState now = drone_->state();
  if (!now.landed || now.armed) {  // airborne, or armed on the ground: make it safe
    tee_.record(dex::failsafe_event(loop_->now(), name(), mission_.settings.failsafe, reason));
    drone_->failsafe(mission_.settings.failsafe);
  }
  failsafe_since_ = loop_->now();
  wait_for_failsafe();
}

void DexProcess::wait_for_failsafe() {
  // Stay up (and alive for the others) until the drone is down, hovering as told, or the
  // failsafe has had ten minutes.
  mid::DroneState s = drone_->state();
  bool done = s.landed || mission_.settings.failsafe == fleet::Failsafe::hover ||
              loop_->now() - failsafe_since_ > 600.0;
  if (done) {
    publish_status(true);
    loop_->stop();
    return;
  }
  loop_->after(0.1 * o_.speed, [this] { wait_for_failsafe(); });
}

}  // namespace

int run_dex_process(const DexProcessOptions& options, const mid::AdapterRegistry& adapters,
                    std::ostream& out, std::ostream& err) {
  DexProcess p(options, out, err);
  return p.run(adapters);
}

}  // namespace eamos::launch
