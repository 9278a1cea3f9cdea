#include "launch/dex_process.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <iostream>
#include <random>
#include <thread>

#include "deploy/mission_file.h"
#include "launch/dex_state.h"
#include "launch/stop_signals.h"
#include "launch/wall_time.h"
#include "mid/home_check.h"

namespace eamos::launch {

namespace {

std::uint64_t process_nonce() {
  std::random_device rd;
  std::uint64_t n = (static_cast<std::uint64_t>(rd()) << 32) ^ rd() ^ static_cast<std::uint64_t>(unix_ns());
  return n == 0 ? 1 : n;
}


/// What this drone's trigger writer keeps for a reader that matched late (a DEX whose
/// reader matched only after the start, discovery still going on, or again after a network
/// cut): twice what one pass through its part of the mission sends, at least the
/// transport's default. Older triggers were acknowledged by every reader matched then.
int durable_triggers(const dex::Mission& m) {
  return static_cast<int>(std::clamp<long long>(2 * m.messages_per_pass(), transport::kDefaultDurableTriggers, 1 << 20));
}

}  // namespace

volatile std::sig_atomic_t g_dex_signal = 0;

namespace {

// SIGTERM (a service stopped, the ground's clean-up), Ctrl-C on a DEX run by hand or the
// hangup of the SSH session it was started from (launch/stop_signals.h): the loop notices
// at its next heartbeat and abandons the mission into the failsafe. A second signal ends
// the process at once (_exit is async-signal-safe; nothing else is done here).
void on_dex_signal(int signal) {
  if (g_dex_signal != 0) _exit(128 + signal);
  g_dex_signal = signal;
}

}  // namespace

int DexProcess::run(const mid::AdapterRegistry& adapters) {
  nonce_ = process_nonce();
  if (!load(adapters) || !check_later_drones() || !open_dds()) return 1;
  on_stop_signals(on_dex_signal);
  if (!wait_for_start() || !begin()) {
    node_->flush(1.0);
    return 1;
  }
  loop_->run_until(o_.time_limit_s + 1000.0);
  dds_trace_->flush();
  node_->flush(1.0);
  if (phase_ == Phase::completed) {
    out_ << name() << ": mission completed\n";
    return 0;
  }
  err_ << "eamos dex: " << name() << ": mission failed: " << error_ << "\n";
  return 1;
}

// The drone's mission file, its loop and its drone from the Adapter Space.
bool DexProcess::load(const mid::AdapterRegistry& adapters) {
  std::vector<std::string> defects;
  if (!deploy::read_mission_file(o_.folder + "/mission.json", mission_, defects)) {
    for (const std::string& d : defects) err_ << d << "\n";
    return false;
  }
  mid::ClockOptions clock;
  clock.mode = mid::ClockMode::real_time;
  clock.speed = o_.speed;
  loop_ = std::make_unique<mid::EventLoop>(clock);
  // Whatever throws on the loop (a bug, a sample nothing checked) ends the mission in the
  // failsafe, never the process with the drone in the air.
  loop_->on_callback_error([this](const std::string& what) { on_internal_error(what); });
  mid::CreateResult made = adapters.create(mission_.settings.adapter, mission_.settings, mission_.type, *loop_);
  if (made.status != mid::CreateStatus::success) {
    err_ << "eamos dex: error: " << name() << ": " << made.message << "\n";
    return false;
  }
  drone_ = std::move(made.drone);
  // Where the vehicle stands, for the ground's homes check: it comes with this DEX's READY.
  if (drone_->has_global_frame()) mid::wait_for_fixes(*loop_, {drone_.get()}, mid::kHomeFixTimeoutS);
  return true;
}

// The drone's DDS participant; every sample is handed to the loop's thread (the inbox),
// and what the wait for the start needs is also noted on the listener's thread.
bool DexProcess::open_dds() {
  transport::DdsHandlers h;
  h.trigger = [this](TriggerSample s) { inbox_.deliver([this, s = std::move(s)] { on_trigger(s); }); };
  h.telemetry = [this](TelemetrySample s) {
    // Another mission's drone must not count as seen, nor overwrite ours in the inbox.
    if (s.telemetry.mission_hash != mission_.hash) {
      inbox_.deliver([this, hash = s.telemetry.mission_hash] { note_foreign(hash); });
      return;
    }
    inbox_.deliver_telemetry(s, [this, s] { on_telemetry(s); });
    wait_cv_.notify_all();
  };
  h.lifecycle = [this](LifecycleSample s) {
    on_lifecycle_waiting(s);
    inbox_.deliver([this, s = std::move(s)] { on_lifecycle(s); });
  };
  h.status = [this](StatusSample s) {
    on_status_waiting(s);
    inbox_.deliver([this, s = std::move(s)] { on_status(s); });
  };
  h.lost = [this](const std::string& hash, int drone, std::uint64_t nonce) {
    inbox_.deliver([this, hash, drone, nonce] { on_lost(hash, drone, nonce); });
  };
  // Logged on the DEX's own thread: the listener that dropped the sample only posts.
  h.dropped = [this](const std::string& line) {
    inbox_.deliver([this, line] { err_ << "eamos dex: " << name() << ": " << line << "\n"; });
  };
  h.limits.drones = static_cast<int>(mission_.fleet.size());
  // This drone's partition, and its own credentials (only its key is in its folder).
  transport::DdsOptions dds = o_.dds;
  dds.mission_hash = mission_.hash;
  dds.self = mission_.self;
  if (!o_.insecure) dds.security_folder = o_.folder + "/security";
  dds.durable_triggers = durable_triggers(mission_);
  std::string error;
  joined_at_ = wall_s();
  node_ = transport::DdsNode::open(dds, std::move(h), error);
  if (!node_) {
    err_ << "eamos dex: error: " << error << "\n";
    return false;
  }
  return true;
}

void DexProcess::on_lifecycle_waiting(const LifecycleSample& s) {
  if (s.mission_hash != mission_.hash) return;
  std::lock_guard<std::mutex> lock(wait_mutex_);
  if (s.kind == LifecycleKind::start) starts_.push_back(s);
  // The barrier ABORT of another launch (one that refused to run beside this one) is not
  // this DEX's: it waits for its own launch.
  bool other_launch = s.run_id == 0 && o_.launch_id != 0 && s.launch_id != o_.launch_id;
  // An ABORT the running DEX would ignore must not end the run before it starts either
  // (the loop logs it when it handles the same sample, on_lifecycle).
  std::string why;
  if (s.kind == LifecycleKind::abort && !other_launch && abort_allowed(s, why)) aborts_.emplace(s.run_id, s.reason);
  wait_cv_.notify_all();
}

void DexProcess::on_status_waiting(const StatusSample& s) {
  if (s.mission_hash != mission_.hash || s.drone != mission_.self || s.nonce == nonce_ || s.run_id == 0) return;
  if (s.phase != Phase::running && s.phase != Phase::failsafe) return;
  std::lock_guard<std::mutex> lock(wait_mutex_);
  if (flown_elsewhere_.empty())
    flown_elsewhere_ = "another DEX of " + name() + " is " + (s.phase == Phase::running ? "flying" : "landing") +
                       " run " + std::to_string(s.run_id) + " of this mission; a second launch of a running " +
                       "deployment is refused (stop the first one, or wait for it to end)";
  wait_cv_.notify_all();
}

std::string DexProcess::flown_elsewhere() {
  std::lock_guard<std::mutex> lock(wait_mutex_);
  return flown_elsewhere_;
}

void DexProcess::refuse(const LifecycleSample& start, const std::string& why) {
  LifecycleSample refused{mission_.hash, mission_.self, LifecycleKind::refused, start.run_id};
  refused.launch_id = start.launch_id;
  refused.nonce = nonce_;
  refused.reason = why;
  node_->write(refused);
}

bool DexProcess::wait_for_start() {
  node_->write(TelemetrySample{0, dex::Telemetry{mission_.hash, mission_.self, drone_->state()}});
  publish_status(true);
  const double lease = o_.dds.lease_s;
  const double deadline = o_.start_timeout_s > 0 ? wall_s() + o_.start_timeout_s : 1e300;
  const double unready_deadline = o_.insecure ? 1e300 : joined_at_ + o_.unready_limit_s;
  bool ready_sent = false;
  std::set<std::uint64_t> refused;
  out_ << name() << ": DEX of mission " << mission_.hash.substr(0, 12) << " waiting for its peers\n" << std::flush;
  for (;;) {
    node_->assert_alive();
    std::vector<LifecycleSample> starts;
    std::optional<std::string> gave_up;
    {
      std::unique_lock<std::mutex> lock(wait_mutex_);
      wait_cv_.wait_for(lock, std::chrono::duration<double>(lease / 4));
      starts.swap(starts_);
      if (aborts_.count(0)) gave_up = aborts_[0];
    }
    if (g_dex_signal != 0) {
      err_ << "eamos dex: " << name() << ": interrupted (" << stop_signal_name(g_dex_signal) << ") before the start\n";
      return false;
    }
    if (gave_up) {
      err_ << "eamos dex: error: " << name() << ": the ground gave up before the start: " << *gave_up << "\n";
      return false;
    }
    publish_heard();
    if (!ready_sent) ready_sent = ready_when_all_seen();
    if (!ready_sent && wall_s() > unready_deadline && !unheard_earlier().empty()) return leave_unready();
    for (const LifecycleSample& s : starts)
      if (std::optional<bool> taken = take_start(s, refused)) return *taken;
    if (wall_s() > deadline) {
      err_ << "eamos dex: error: " << name() << ": no start within " << o_.start_timeout_s
           << " s; is `eamos launch` running on domain " << o_.dds.domain << "?\n";
      return false;
    }
  }
}

// How many drones this DEX has heard from, for the ground's waves: when it changed, at
// most once a second (every other DEX reads the status too).
void DexProcess::publish_heard() {
  int heard = static_cast<int>(inbox_.latest().size());
  if (heard == heard_published_ || wall_s() < heard_published_at_ + 1.0) return;
  heard_published_ = heard;
  heard_published_at_ = wall_s();
  publish_status(true);
}

// With DDS Security, a drone not heard from by now has a handshake with this DEX that does
// not complete; Cyclone would give it up at kHandshakeGiveUpS, where Debian's build can
// crash. Leaving the domain first ends this DEX cleanly (nothing has flown); a service
// restarts it and its handshakes begin again.
std::vector<std::string> DexProcess::unheard_earlier() {
  std::map<int, TelemetrySample> seen = inbox_.latest();
  std::vector<std::string> missing;
  for (int d = 0; d < static_cast<int>(mission_.fleet.size()); ++d)
    if (d != mission_.self && !seen.count(d) &&
        std::find(o_.later_drones.begin(), o_.later_drones.end(), mission_.fleet[d]) == o_.later_drones.end())
      missing.push_back(mission_.fleet[d]);
  return missing;
}

bool DexProcess::check_later_drones() {
  for (const std::string& later : o_.later_drones)
    if (std::find(mission_.fleet.begin(), mission_.fleet.end(), later) == mission_.fleet.end()) {
      err_ << "eamos dex: error: --later-drones names '" << later << "', which is not a drone of this mission; "
           << "give the names of the mission's fleet, separated by commas\n";
      return false;
    }
  return true;
}

bool DexProcess::leave_unready() {
  std::string missing;
  for (const std::string& d : unheard_earlier()) missing += (missing.empty() ? "" : ", ") + d;
  err_ << "eamos dex: error: " << name() << ": not ready " << o_.unready_limit_s
       << " s after joining DDS: nothing heard from " << missing
       << " (their DEX is not running, or its DDS Security handshake with this one did not complete); "
       << "leaving before Cyclone DDS gives the handshakes up; start this DEX again\n";
  return false;
}

// READY once a telemetry sample came from every other drone, not only those whose telemetry
// this mission reads: a sample from each shows the channel to it is up (with DDS Security,
// its handshake done). A handshake that failed (it times out under heavy loss and Cyclone
// does not retry it) would otherwise leave a trigger to that drone undelivered and the
// mission waiting for ever, with no liveliness ever lost: such a DEX stays unready and the
// ground's barrier refuses to start.
bool DexProcess::ready_when_all_seen() {
  std::map<int, TelemetrySample> seen = inbox_.latest();
  for (int d = 0; d < static_cast<int>(mission_.fleet.size()); ++d)
    if (d != mission_.self && !seen.count(d)) return false;
  LifecycleSample ready;
  ready.mission_hash = mission_.hash;
  ready.drone = mission_.self;
  ready.kind = LifecycleKind::ready;
  ready.nonce = nonce_;
  ready.launch_id = o_.launch_id;
  ready.fix = drone_->global_fix();
  ready.home_x = mission_.settings.home.x;
  ready.home_y = mission_.settings.home.y;
  ready.home_tolerance = mission_.settings.home_tolerance_m;
  ready.speed = o_.speed;  // the ground refuses to start a fleet whose DEXes run at other speeds
  node_->write(ready);
  out_ << name() << ": ready\n" << std::flush;
  return true;
}

std::optional<bool> DexProcess::take_start(const LifecycleSample& s, std::set<std::uint64_t>& refused) {
  bool mine = s.drone == transport::kGround && static_cast<int>(s.nonces.size()) > mission_.self &&
              s.nonces[mission_.self] == nonce_ && (o_.launch_id == 0 || s.launch_id == o_.launch_id);
  std::string elsewhere = mine ? flown_elsewhere() : "";
  if (!elsewhere.empty()) {
    err_ << "eamos dex: error: " << name() << ": refusing run " << s.run_id << ": " << elsewhere << "\n";
    refuse(s, elsewhere);
    node_->flush(1.0);
    return false;
  }
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
  return std::nullopt;
}

bool DexProcess::begin() {
  if (!reach_start_instant()) return false;
  transport_ = std::make_unique<transport::DdsTransport>(*node_, start_.run_id);
  last_trigger_seq_.assign(mission_.fleet.size(), 0);
  // What the status reports (triggers sent) and a failed write are acted on as they happen.
  transport_->on_change([this] { schedule_settle(); });
  open_traces();
  const double rate = o_.state_rate_hz > 0 ? o_.state_rate_hz : state_rate_for(static_cast<int>(mission_.fleet.size()));
  state_period_s = rate >= kFullStateRateHz ? 0.0 : o_.speed / rate;
  make_engine();
  watch_run();
  publish_status(true);
  engine_->start();
  heartbeat();
  settle();
  return true;
}

bool DexProcess::reach_start_instant() {
  // Mission time 0 is the start instant the ground chose, the same on every drone, also
  // for a DEX that got START late: its loop runs from that instant, catching up.
  double lease = o_.dds.lease_s;
  while (unix_ns() < start_.start_at_ns) {
    node_->assert_alive();
    // Another DEX of this drone that was discovered only after the START came.
    std::string elsewhere = flown_elsewhere();
    if (!elsewhere.empty()) {
      error_ = "refusing run " + std::to_string(start_.run_id) + ": " + elsewhere;
      err_ << "eamos dex: error: " << name() << ": " << error_ << "\n";
      refuse(start_, elsewhere);
      return false;
    }
    double left = (start_.start_at_ns - unix_ns()) / 1e9;
    std::this_thread::sleep_for(std::chrono::duration<double>(std::min(left, lease / 4)));
  }
  loop_->set_wall_origin(wall_s() + (start_.start_at_ns - unix_ns()) / 1e9);
  {
    // A drone that refused this run (speed mismatch) did so before anyone moved.
    std::lock_guard<std::mutex> lock(wait_mutex_);
    auto it = aborts_.find(start_.run_id);
    if (it != aborts_.end()) {
      error_ = "run " + std::to_string(start_.run_id) + " was aborted before it started: " + it->second;
      err_ << "eamos dex: " << name() << ": " << error_ << "\n";
      return false;
    }
  }
  return true;
}

// This drone's trace: to the ground over DDS, the live log, and its own file if asked.
void DexProcess::open_traces() {
  dds_trace_ = std::make_unique<DdsTraceSink>(*node_, *loop_, mission_.hash, start_.run_id, mission_.self);
  tee_.add(dds_trace_.get());
  if (o_.log) {
    live_ = std::make_unique<dex::LiveLog>(out_);
    tee_.add(live_.get());
  }
  if (!o_.trace_file.empty()) {
    trace_file_.open(o_.trace_file, std::ios::trunc);
    if (trace_file_) {
      jsonl_ = std::make_unique<dex::JsonlTrace>(trace_file_, mission_.fleet);
      // This drone's own copy: the ground's merged trace does not depend on it.
      jsonl_->on_write_error([this](const std::string& why) {
        err_ << name() << ": cannot write trace '" << o_.trace_file << "' (" << why << "); it stops here\n";
      });
      tee_.add(jsonl_.get());
    } else {
      err_ << name() << ": cannot write trace '" << o_.trace_file << "'\n";
    }
  }
}

void DexProcess::make_engine() {
  dex::EngineHooks hooks;
  hooks.transport = transport_.get();
  hooks.trace = &tee_;
  hooks.on_failure = [this](const dex::Failure& f) {
    abandon(dex::failure_text(f), f, true);
  };
  hooks.on_end = [this] {
    end_reached_ = true;
    publish_status();
    schedule_settle();
  };
  // Idle now, not later: the lead's FINISHED carries the instant the last drone
  // went idle (StatusSample::since), which is the mission's duration.
  hooks.on_idle = [this] {
    publish_status();
    schedule_settle();
  };
  engine_ = std::make_unique<dex::Engine>(mission_, *drone_, *loop_, hooks);
  start_separation();
  phase_ = Phase::running;
  inbox_.attach(*loop_, [this](const TelemetrySample& s) { seed_telemetry(s); });
  drone_->subscribe([this](const mid::DroneState& s) {
    separation_->update(mission_.self, s);
    engine_->properties_changed(mission_.self);
    publish_state(s);
  });
}

void DexProcess::publish_state(const mid::DroneState& s) {
  if (state_due_) {  // the period's timer is set: it sends the newest
    state_due_ = s;
    return;
  }
  // A tolerance, or a timer due at the period's end could find itself a rounding short of
  // it and set itself again for the same instant, for ever.
  const double now = loop_->now();
  if (state_period_s <= 0.0 || now - state_published_at_ >= state_period_s - 1e-9) return send_state(s);
  // The newest state goes out at the period's end: a drone that stopped is not left
  // standing elsewhere in the others' view.
  state_due_ = s;
  loop_->at(state_published_at_ + state_period_s, [this] {
    mid::DroneState due = *state_due_;
    state_due_.reset();
    send_state(due);
  });
}

void DexProcess::send_state(const mid::DroneState& s) {
  state_published_at_ = loop_->now();
  transport_->publish(std::make_shared<const dex::Telemetry>(dex::Telemetry{mission_.hash, mission_.self, s}));
}

double state_rate_for(int drones) {
  if (drones <= kFullRateDrones) return kFullStateRateHz;
  double ratio = static_cast<double>(kFullRateDrones) / drones;
  return std::max(1.0, kFullStateRateHz * ratio * ratio);
}

void DexProcess::watch_run() {
  // A loop that could not run for longer than the lease (the process was stopped, the
  // machine starved it) has been given up by the others and must not replay what fell due
  // meanwhile, every overdue action at once with back-dated times: it abandons first.
  loop_->on_stall(o_.dds.lease_s, [this](double stalled_s) { on_stall(stalled_s); });
  loop_->at(o_.time_limit_s, [this] {
    if (phase_ != Phase::running) return;
    abandon("mission did not complete within " + std::to_string(o_.time_limit_s) +
                " s of mission time; raise --time-limit if it is meant to run longer",
            std::nullopt, true);
  });
}

void DexProcess::start_separation() {
  dex::SeparationHooks hooks;
  hooks.trace = &tee_;
  hooks.on_stuck = [this](const std::string& why) { abandon(why, std::nullopt, true); };
  separation_ = std::make_unique<dex::SeparationGuard>(mission_, *loop_, hooks);
  separation_->fly(mission_.self, *drone_, mission_.settings.limits);
  separation_->update(mission_.self, drone_->state());
}

int run_dex_process(const DexProcessOptions& options, const mid::AdapterRegistry& adapters,
                    std::ostream& out, std::ostream& err) {
  DexProcess p(options, out, err);
  return p.run(adapters);
}

}  // namespace eamos::launch
