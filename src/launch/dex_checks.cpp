// What a DEX checks in a sample before it acts on it, beyond the field rules of
// from_wire and the sender binding of DdsNode: even an authenticated peer (a drone whose
// key was stolen, a DEX with a bug) must not make this drone do what its own mission does
// not say. docs/security.md lists the rules. A sample that breaks one is ignored and
// logged once per sender and rule; it never stops the DEX.
#include <algorithm>
#include <iostream>

#include "launch/dex_state.h"
#include "launch/wall_time.h"

namespace eamos::launch {

std::string DexProcess::who(int drone) const {
  if (drone == transport::kGround) return "the ground";
  if (drone >= 0 && drone < static_cast<int>(mission_.fleet.size())) return mission_.fleet[drone];
  return "drone " + std::to_string(drone);
}

void DexProcess::reject(int sender, const std::string& what, const std::string& why) {
  // What was logged is remembered up to a bound: a peer sending ever new faults (each replay
  // names its own sequence number) must not grow this process's memory.
  if (rejected_.size() > kMaxRemembered) return;
  if (rejected_.size() == kMaxRemembered) {
    rejected_.insert("");
    err_ << name() << ": more ignored samples than " << kMaxRemembered << " kinds; no longer logging them\n";
    return;
  }
  if (rejected_.insert(std::to_string(sender) + " " + what + " " + why).second)
    err_ << name() << ": ignored a " << what << " sample from " << who(sender) << ": " << why << "\n";
}

bool DexProcess::trigger_allowed(const TriggerSample& s, std::string& why) const {
  const dex::Message& m = s.message;
  if (m.from == mission_.self) {
    why = "it names this drone as its sender";
    return false;
  }
  if (m.kind == dex::Message::Kind::arrived) {
    if (s.to == transport::kEveryDrone) return true;  // on_trigger took it only from a drone its clone waits for
    why = "an arrival at sync point " + std::to_string(m.meg) + " is sent to every drone, not to one";
    return false;
  }
  int node = mission_.find(m.meg, m.from);
  if (m.kind == dex::Message::Kind::cancel) {
    // Cancels go to every drone; one for a condition this mission does not hold does nothing.
    if (node >= 0 && mission_.nodes[node].kind != graph::MegKind::condition) {
      why = "node " + std::to_string(m.meg) + " of " + who(m.from) + " is not a condition and cancels nothing";
      return false;
    }
    return true;
  }
  if (node < 0) {
    why = "node " + std::to_string(m.meg) + " of " + who(m.from) + " is not in this drone's mission";
    return false;
  }
  // It must end in a node of this drone, on the branch it says it ended with.
  for (int a : mission_.nodes[node].out) {
    const dex::Arc& arc = mission_.arcs[a];
    if (mission_.nodes[arc.to].internal && (arc.branch == graph::Branch::any || arc.branch == m.branch)) return true;
  }
  why = "node " + std::to_string(m.meg) + " of " + who(m.from) + " triggers nothing of this drone on that branch";
  return false;
}

bool DexProcess::abort_allowed(const LifecycleSample& s, std::string& why) const {
  if (!(s.t >= 0.0) || s.t > o_.time_limit_s + 1000.0) {
    why = "its mission time is outside the run";
    return false;
  }
  if (s.failure) {
    bool known = false;
    for (const std::string& d : mission_.fleet) known = known || d == s.failure->drone;
    if (!known) {
      why = "the failed drone it names is not in the mission";
      return false;
    }
  }
  return true;
}

bool DexProcess::finish_agreed(int lead, std::string& why) const {
  if (engine_->busy()) {
    why = "this drone is still busy";
    return false;
  }
  auto it = statuses_.find(lead);
  if (it == statuses_.end() || !it->second.end_reached) {
    why = "its sender has not reached the mission's end";
    return false;
  }
  FleetCounters c;
  if (!others_idle(false, c, why)) return false;
  if (c.sent != c.received) {
    why = "triggers are still in flight";
    return false;
  }
  return true;
}

void DexProcess::on_finished(const LifecycleSample& s) {
  // Only the lead may say it, and only when this drone sees what the lead saw: every
  // drone idle and nothing in flight. The statuses that show it may still be on their
  // way: a FINISHED not agreed with yet is kept and checked again as statuses come.
  std::string why;
  if (s.drone == transport::kGround) return reject(s.drone, "finished", "only the lead drone ends a mission");
  if (finish_agreed(s.drone, why)) return complete();
  if (!pending_finished_) pending_since_ = wall_s();
  pending_finished_ = s;
}

void DexProcess::check_pending_finished() {
  if (!pending_finished_ || phase_ != Phase::running) return;
  std::string why;
  if (finish_agreed(pending_finished_->drone, why)) return complete();
  // Statuses arrive within moments; one not agreed with after the lease is refused.
  if (wall_s() - pending_since_ > o_.dds.lease_s) reject(pending_finished_->drone, "finished", why);
}

// Every drone reads every arrival; one it does not wait for (another sync point, or a
// drone its clone does not wait for) is not for it.
bool DexProcess::waits_for_arrival(const dex::Message& m) const {
  if (m.kind != dex::Message::Kind::arrived) return false;
  int node = mission_.find(m.meg, mission_.self);
  if (node < 0 || mission_.nodes[node].waits < 0) return false;
  const std::vector<int>& set = mission_.drone_sets[mission_.nodes[node].waits];
  return m.from != mission_.self && std::binary_search(set.begin(), set.end(), m.from);
}

}  // namespace eamos::launch
