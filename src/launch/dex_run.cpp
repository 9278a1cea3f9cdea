// The DEX process once the mission runs: what it receives, its status, how the mission
// ends (FINISHED from the lead, or ABORT from anyone) and the failsafe. docs/faults.md
// says per fault what happens.
#include <algorithm>
#include <cstdio>
#include <iostream>

#include "diag/number.h"
#include "dex/latency.h"
#include "dex/runner.h"
#include "launch/dex_state.h"
#include "launch/stop_signals.h"
#include "launch/wall_time.h"

namespace eamos::launch {

void DexProcess::heartbeat() {
  // The loop's own heartbeat, a few times per lease: liveliness is asserted only while the
  // loop runs, so a hung DEX is lost like a dead one; a signal and a FINISHED nobody agreed
  // with are noticed here. Everything else is done when the event that changes it comes
  // (settle): a drone waiting at a barrier wakes only for this.
  node_->assert_alive();
  if (phase_ == Phase::running && g_dex_signal != 0)
    abandon(name() + "'s DEX was interrupted (" + stop_signal_name(g_dex_signal) + ")", std::nullopt, true);
  check_pending_finished();
  loop_->after(heartbeat_s() * o_.speed, [this] { heartbeat(); });
}

void DexProcess::schedule_settle() {
  // Once per burst of changes, after the callback that made them (the engine may be in
  // the middle of a step when it sends).
  if (settle_scheduled_) return;
  settle_scheduled_ = true;
  loop_->after(0.0, [this] {
    settle_scheduled_ = false;
    settle();
  });
}

void DexProcess::settle() {
  if (phase_ == Phase::running && transport_->write_errors() > 0) {
    // A trigger that did not go out would leave another drone waiting for ever.
    abandon("DDS could not send a trigger or telemetry sample (write failed or blocked too long)", std::nullopt,
            true);
  }
  publish_status();
  check_finished();
  check_pending_finished();
}

bool DexProcess::ours(const std::string& hash, std::uint64_t run) {
  if (hash != mission_.hash) {
    note_foreign(hash);
    return false;
  }
  if (run != start_.run_id) {
    if (stale_runs_.size() < kMaxRemembered && stale_runs_.insert(run).second)
      err_ << name() << ": ignoring messages of run " << run << " (this drone is in run " << start_.run_id << ")\n";
    return false;
  }
  return true;
}

void DexProcess::note_foreign(const std::string& hash) {
  if (foreign_.size() < kMaxRemembered && foreign_.insert(hash).second)
    err_ << name() << ": ignoring messages of another mission (hash " << hash.substr(0, 12)
         << "…) on DDS domain " << o_.dds.domain << "\n";
}

void DexProcess::on_trigger(const TriggerSample& s) {
  if (!ours(s.message.mission_hash, s.run_id) || (s.to != mission_.self && s.to != transport::kEveryDrone)) return;
  // An arrival at a sync point goes to every drone; only the clone holders that wait for
  // its sender take it.
  if (s.to == transport::kEveryDrone && !waits_for_arrival(s.message)) return;
  std::string why;
  if (!trigger_allowed(s, why)) return reject(s.message.from, "trigger", why);
  // Reliable delivery never repeats a sample: one numbered at or below the newest accepted
  // one from its sender is a replay (trigger_allowed checked the sender's range).
  std::uint64_t& last = last_trigger_seq_[s.message.from];
  if (s.seq <= last)
    return reject(s.message.from, "trigger", "sequence number " + std::to_string(s.seq) + " was already received");
  last = s.seq;
  // Only what was accepted is counted: a dropped sample counted as received would leave
  // Σsent ≠ Σreceived and the mission waiting for ever.
  if (s.message.kind != dex::Message::Kind::cancel) ++received_;
  if (phase_ == Phase::running) {
    dex::TraceEvent event = dex::message_event(mission_, s.message, mission_.self, loop_->now());
    if (too_late(event)) return;
    tee_.record(event);
    engine_->receive(s.message);
  }
  settle();
}

bool DexProcess::too_late(const dex::TraceEvent& event) {
  double bound = o_.max_trigger_latency_s;
  if (bound <= 0 || dex::latency_of(event) <= bound) return false;
  // A late trigger means the drones no longer act together as planned (one waited, or
  // the mission's timing moved): the bound makes that a fault, not a course to follow.
  char limit[64];
  std::snprintf(limit, sizeof limit, ", later than --max-trigger-latency %g s", bound);
  abandon(dex::describe_late(dex::late_message(event, mission_.fleet)) + limit, std::nullopt, true);
  tee_.record(event);  // recorded after the failsafe it caused, and never acted on
  return true;
}

void DexProcess::seed_telemetry(const TelemetrySample& s) {
  // Before the start: the newest state of each drone of this mission, run 0 (the initial
  // state every DEX publishes while it waits) or this run (a drone that started first).
  if (s.telemetry.mission_hash != mission_.hash || s.telemetry.from == mission_.self) return;
  if (s.run_id != 0 && s.run_id != start_.run_id) return;
  separation_->update(s.telemetry.from, s.telemetry.state);
  engine_->receive(std::make_shared<const dex::Telemetry>(s.telemetry));
}

void DexProcess::on_telemetry(const TelemetrySample& s) {
  if (s.telemetry.mission_hash != mission_.hash) return note_foreign(s.telemetry.mission_hash);
  if (s.telemetry.from == mission_.self) return;
  // Once running, only this run's telemetry: run 0 now comes from a DEX that was started
  // again and stands at home, not from the drone that flies.
  if (s.run_id != start_.run_id) return;
  separation_->update(s.telemetry.from, s.telemetry.state);
  engine_->receive(std::make_shared<const dex::Telemetry>(s.telemetry));
}

void DexProcess::on_lifecycle(const LifecycleSample& s) {
  if (s.kind == LifecycleKind::start) return on_other_start(s);
  if (s.kind == LifecycleKind::ready || s.kind == LifecycleKind::refused) return;
  if (!ours(s.mission_hash, s.run_id)) return;
  if (s.kind == LifecycleKind::abort) {
    std::string why;
    if (!abort_allowed(s, why)) return reject(s.drone, "abort", why);
    abandon("aborted by " + who(s.drone) + ": " + s.reason, s.failure, false);
  } else if (s.kind == LifecycleKind::finished && phase_ == Phase::running) {
    on_finished(s);
  }
}

void DexProcess::on_other_start(const LifecycleSample& s) {
  // A second ground that took this process's READY (a DEX started on its own, which any
  // launch may start) must hear that it runs a run already, and fail its own.
  bool names_us = s.mission_hash == mission_.hash && s.drone == transport::kGround && s.run_id != start_.run_id &&
                  static_cast<int>(s.nonces.size()) > mission_.self && s.nonces[mission_.self] == nonce_;
  if (!names_us) return;
  std::string why = name() + "'s DEX is already running run " + std::to_string(start_.run_id) +
                    " of this mission; a second launch of a running deployment is refused";
  err_ << name() << ": refused run " << s.run_id << " of another launch: it already runs run " << start_.run_id
       << "\n";
  refuse(s, why);
}

void DexProcess::on_status(const StatusSample& s) {
  if (s.mission_hash != mission_.hash) return note_foreign(s.mission_hash);
  if (s.run_id != start_.run_id || s.drone == mission_.self) return;
  // Bound to the process START named for that drone: another process with the drone's
  // credentials (a restarted DEX, a copy) does not speak for it.
  if (s.drone >= static_cast<int>(start_.nonces.size()) || start_.nonces[s.drone] != s.nonce)
    return reject(s.drone, "status", "it comes from another process than the one this run was started with");
  statuses_[s.drone] = s;
  // The lead (the one drone that reached the end) asks for a termination wave: answer
  // once with this drone's counters as they are now.
  if (s.end_reached && s.wave > wave_answered_) {
    wave_answered_ = s.wave;
    publish_status(true);
  }
  if (termination_) termination_->report({s.drone, s.wave, s.busy, s.sent, s.received});
  settle();  // the lead's next wave, or a FINISHED this drone can now agree with
}

void DexProcess::on_lost(const std::string& hash, int drone, std::uint64_t nonce) {
  if (hash != mission_.hash || drone == mission_.self || phase_ != Phase::running) return;
  // Only the processes START named: a leftover or restarted DEX going away is not a loss.
  if (drone < 0 || drone >= static_cast<int>(start_.nonces.size()) || start_.nonces[drone] != nonce) return;
  auto it = statuses_.find(drone);
  if (it != statuses_.end() && (it->second.phase == Phase::completed || it->second.phase == Phase::failed))
    return;  // it finished and left: not lost
  std::string lost = drone >= 0 && drone < static_cast<int>(mission_.fleet.size()) ? mission_.fleet[drone] : "?";
  abandon(lost + " lost: no liveliness for " + diag::number_text(o_.dds.lease_s) +
              " s (its DEX stopped, hung or is unreachable)",
          std::nullopt, true);
}

StatusSample DexProcess::status_now(Phase phase) const {
  StatusSample s;
  s.mission_hash = mission_.hash;
  s.drone = mission_.self;
  s.run_id = start_.run_id;
  s.nonce = nonce_;
  s.phase = phase;
  s.busy = engine_ && engine_->busy();
  s.end_reached = end_reached_;
  s.sent = transport_ ? transport_->sent() : 0;
  s.received = received_;
  s.activations = engine_ ? engine_->activations() : 0;
  s.wave = termination_ ? termination_->wave() : wave_answered_;
  s.since = last_status_ && last_status_->busy == s.busy ? last_status_->since : (loop_ ? loop_->now() : 0.0);
  s.state = drone_->state();
  s.heard = heard_published_;
  return s;
}

void DexProcess::publish_status(bool force) {
  StatusSample s = status_now(phase_);
  if (!force && last_status_) {
    StatusChange change = status_change(*last_status_, s);
    if (change == StatusChange::none) return;
    if (change == StatusChange::counters && defer_counters()) return;
  }
  node_->write(s);
  last_status_ = s;
  status_published_at_ = wall_s();
}

bool DexProcess::defer_counters() {
  double gap = counters_gap_for(static_cast<int>(mission_.fleet.size()), o_.dds.lease_s);
  double due = status_published_at_ + gap;
  if (gap <= 0 || wall_s() >= due || !loop_) return false;
  if (!counters_due_) {
    counters_due_ = true;
    loop_->after((due - wall_s()) * o_.speed, [this] {
      counters_due_ = false;
      if (phase_ == Phase::running) publish_status();
    });
  }
  return true;
}

double counters_gap_for(int drones, double lease_s) { return drones <= kFullRateDrones ? 0.0 : lease_s / 4; }

StatusChange status_change(const StatusSample& before, const StatusSample& now) {
  if (before.phase != now.phase || before.busy != now.busy || before.end_reached != now.end_reached ||
      before.wave != now.wave)
    return StatusChange::other;
  if (before.sent != now.sent || before.received != now.received) return StatusChange::counters;
  return StatusChange::none;
}

// Only the lead (it ran the end node) decides, by termination waves (launch/termination.h);
// everyone else follows its FINISHED. Waves start once the newest statuses look over, so an
// active fleet is not asked at every change.
void DexProcess::check_finished() {
  if (phase_ != Phase::running || !end_reached_) return;
  if (!termination_) termination_.emplace(static_cast<int>(mission_.fleet.size()));
  FleetCounters c;
  std::string why;
  if (engine_->busy() || !others_idle(true, c, why) || c.sent != c.received) {
    termination_->reset();
    return;
  }
  if (termination_->collecting()) return;
  if (!termination_->terminated()) {
    std::uint64_t wave = termination_->start_wave();
    termination_->report({mission_.self, wave, false, transport_->sent(), received_});
    publish_status(true);  // asks every drone for its answer
    // A wave nobody else answers (a fleet of one) is complete already: no status will come
    // in to wake this check, so it goes on by itself.
    if (termination_->wave_complete()) schedule_settle();
    return;
  }
  double idle_since = std::max(last_status_ ? last_status_->since : loop_->now(), c.others_idle_since);
  LifecycleSample finished{mission_.hash, mission_.self, LifecycleKind::finished, start_.run_id};
  // The mission ended when its last drone went idle, not when the lead noticed.
  finished.t = idle_since;
  node_->write(finished);
  complete();
}

bool DexProcess::others_idle(bool running_only, FleetCounters& c, std::string& why) const {
  c = FleetCounters{transport_->sent(), received_, 0.0};
  for (int d = 0; d < static_cast<int>(mission_.fleet.size()); ++d) {
    if (d == mission_.self) continue;
    auto it = statuses_.find(d);
    if (it == statuses_.end() || it->second.busy || (running_only && it->second.phase != Phase::running)) {
      why = who(d) + " is still busy";
      return false;
    }
    c.sent += it->second.sent;
    c.received += it->second.received;
    c.others_idle_since = std::max(c.others_idle_since, it->second.since);
  }
  return true;
}

void DexProcess::complete() {
  phase_ = Phase::completed;
  publish_status(true);
  loop_->stop();
}

void DexProcess::abandon(const std::string& reason, const std::optional<dex::Failure>& failure, bool broadcast) {
  if (phase_ != Phase::running) return;
  phase_ = Phase::failsafe;  // failed once the failsafe has ended (on_failsafe_over)
  error_ = reason;
  // This drone's failsafe, then the ABORT that starts everyone else's, and only then the
  // log and the trace (dex::abandon_drones).
  if (separation_) separation_->halt();
  std::vector<dex::FailsafeDrone> self = {{engine_.get(), drone_.get(), &mission_.settings}};
  dex::abandon_drones(self, loop_->now(), reason, &tee_, [&] {
    if (broadcast) {
      LifecycleSample abort{mission_.hash, mission_.self, LifecycleKind::abort, start_.run_id};
      abort.reason = reason;
      abort.failure = failure;
      abort.t = loop_->now();
      node_->write(abort);
    }
    err_ << name() << ": " << reason << "\n";
  });
  // Stay up (and alive for the others) until the failsafe is over as dex::failsafe_over
  // says, the rule `eamos run` follows too. Down alone is not over: a DEX that ended at the
  // touchdown left its vehicle armed on the ground (seen on PX4 SITL) and reported it so.
  failsafe_wait_ = std::make_unique<dex::FailsafeWait>(*loop_, std::move(self), 0.1 * o_.speed,
                                                       [this] { on_failsafe_over(); }, &tee_);
  failsafe_wait_->start();
}

void DexProcess::on_stall(double stalled_s) {
  char text[160];
  std::snprintf(text, sizeof text,
                "'s DEX stalled for %.2f s, longer than the liveliness lease (%g s); abandoning instead of "
                "running what fell due meanwhile",
                stalled_s, o_.dds.lease_s);
  abandon(name() + text, std::nullopt, true);
}

void DexProcess::on_internal_error(const std::string& what) {
  err_ << name() << ": internal error: " << what << "\n";
  abandon("internal error in the DEX of " + name() + ": " + what, std::nullopt, true);
}

void DexProcess::on_failsafe_over() {
  // Its final state: the ground reports this one, not the one at the abort.
  phase_ = Phase::failed;
  publish_status(true);
  loop_->stop();
}

}  // namespace eamos::launch
