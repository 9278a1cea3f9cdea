#include "dex/engine.h"

#include <algorithm>
#include <cmath>

#include "dex/engine_do.h"
#include "dex/epoch.h"

namespace eamos::dex {

using graph::ArcKind;
using graph::Branch;
using graph::MegKind;
using lang::ControlKind;

Engine::Engine(const Mission& mission, mid::Drone& drone, mid::EventLoop& loop, EngineHooks hooks)
    : m_(mission), drone_(drone), loop_(loop), hooks_(std::move(hooks)), state_(mission.nodes.size()),
      board_drones_(mission.reads) {
  std::sort(board_drones_.begin(), board_drones_.end());
  board_drones_.erase(std::unique(board_drones_.begin(), board_drones_.end()), board_drones_.end());
  board_.resize(board_drones_.size());
  for (std::size_t i = 0; i < m_.nodes.size(); ++i) reset_counters(static_cast<int>(i));
  if (hooks_.trace) {
    drone_.set_message_sink([this](const std::string& text) {
      TraceEvent e;
      e.t = loop_.now();
      e.drone = drone_.name();
      e.event = "vehicle";
      e.text = text;
      hooks_.trace->record(e);
    });
  }
  // A fault of the drone no action carried (it left its geofence between actions): the
  // drone has already commanded its failsafe; the mission fails as on a failed action.
  drone_.set_fault_sink([this](const mid::ActionEnd& e) {
    if (!halted_ && hooks_.on_failure) hooks_.on_failure({m_.fleet[m_.self], "", 0, e.reason, e.failure, e.detail});
  });
}

Engine::~Engine() {
  drone_.set_message_sink(nullptr);
  drone_.set_fault_sink(nullptr);
}

void Engine::start() {
  for (std::size_t i = 0; i < m_.nodes.size(); ++i) {
    const Node& n = m_.nodes[i];
    if (n.internal && n.kind == MegKind::init) {
      queue_.push_back({static_cast<int>(i), ArcKind::exec, false});
      ++state_[i].exec_pending;  // the start itself is init's one prerequisite
    }
  }
  drain();
}

double property_of(const mid::DroneState& s, const std::string& name) {
  if (name == "X") return s.x;
  if (name == "Y") return s.y;
  if (name == "Z") return s.z;
  if (name == "Battery") return s.battery;
  if (name == "Armed") return s.armed ? 1 : 0;
  if (name == "Landed") return s.landed ? 1 : 0;
  auto it = s.sensors.find(name);
  return it == s.sensors.end() ? 0.0 : it->second;
}

double Engine::property(int drone, const std::string& name) const {
  if (drone == m_.self) return property_of(drone_.state(), name);
  int slot = board_slot(drone);
  if (slot < 0 || !board_[slot]) return NAN;
  return property_of(board_[slot]->state, name);
}

int Engine::board_slot(int drone) const {
  auto it = std::lower_bound(board_drones_.begin(), board_drones_.end(), drone);
  return it != board_drones_.end() && *it == drone ? static_cast<int>(it - board_drones_.begin()) : -1;
}

void Engine::trace(const Node& n, const std::string& event, const std::string& outcome) {
  if (!hooks_.trace) return;
  TraceEvent e;
  e.t = loop_.now();
  e.drone = m_.fleet[m_.self];
  e.event = event;
  e.name = n.kind == MegKind::condition ? lang::control_name(n.control) : n.name;
  e.line = n.line;
  e.col = n.col;
  e.text = n.text;
  e.outcome = outcome;
  e.node = n.meg;
  hooks_.trace->record(e);
}

// Local triggers go through a queue, not recursion: a long chain of instantaneous nodes
// (forks, terminals) must not deepen the stack.
void Engine::deliver(int node, ArcKind kind, bool from_terminal) {
  queue_.push_back({node, kind, from_terminal});
  drain();
}

long long Engine::epoch_of(int scope) const {
  auto it = epoch_.find(scope);
  return it == epoch_.end() ? 0 : it->second;
}

// A node whose body started a new run since its counters were last set starts afresh.
void Engine::refresh(int node) {
  const Node& n = m_.nodes[node];
  if (n.scope < 0) return;
  State& s = state_[node];
  long long e = epoch_of(n.scope);
  if (s.epoch == e) return;
  s.epoch = e;
  reset_counters(node);
}

void Engine::reset_counters(int node) {
  const Node& n = m_.nodes[node];
  State& s = state_[node];
  s.exec_pending = n.exec_in;
  s.back_pending = n.back_in;
  s.local_ready = n.exec_in == 0;
  s.arrivals_pending = n.waits_count;
}

void Engine::drain() {
  if (draining_) return;
  draining_ = true;
  while (!queue_.empty() && !halted_) {
    Delivery d = queue_.front();
    queue_.pop_front();
    refresh(d.node);
    State& s = state_[d.node];
    const Node& n = m_.nodes[d.node];
    if (d.arrival) {
      --s.arrivals_pending;
      pass_barrier_when_complete(d.node);
      continue;
    }
    switch (d.kind) {
      case ArcKind::exec:
        if (--s.exec_pending <= 0) {
          s.exec_pending = n.exec_in;  // ready for the next activation (loops)
          if (graph::is_sync_point(n.kind)) arrive(d.node);
          else activate(d.node, false);
        }
        break;
      case ArcKind::back:
        if (--s.back_pending <= 0) {
          s.back_pending = n.back_in;
          schedule_iteration(d.node);
        }
        break;
      case ArcKind::partner:
        // A released terminal ends without its branch; it releases its own partner only
        // when a condition released it (Do's skip), never back to the partner that did.
        s.exec_pending = n.exec_in;
        end(d.node, Branch::any, d.from_terminal, true);
        break;
      case ArcKind::stop: stop_watching(d.node); break;
    }
  }
  draining_ = false;
  if (active_ == 0 && !halted_ && hooks_.on_idle) hooks_.on_idle();
}

// Every iteration goes through the event loop: a loop whose body takes no time would
// otherwise hold the loop's thread for ever, and no timer (the time limit), liveliness
// assertion or signal would get its turn. One that keeps taking no time fails.
void Engine::schedule_iteration(int node) {
  const Node& n = m_.nodes[node];
  State& s = state_[node];
  if (loop_.now() > s.iteration_started) {
    s.instant_iterations = 0;
  } else if (++s.instant_iterations >= kMaxInstantIterations) {
    if (hooks_.on_failure)
      hooks_.on_failure({m_.fleet[m_.self], lang::control_name(n.control), n.line,
                         std::to_string(kMaxInstantIterations) +
                             " iterations in a row took no mission time; its repeat branch must wait for "
                             "something that takes time (an action, PauseFor, Wait*)"});
    return;
  }
  ++active_;  // not idle while the next iteration waits for its turn
  s.next_iteration = loop_.defer([this, node] {
    state_[node].next_iteration = mid::kNoTimer;
    --active_;
    activate(node, true);
    drain();
  });
}

// This drone's own arcs into a sync point have all fired: it has arrived. It tells the
// other clone holders once, and its own clone, if it holds one, passes once every other
// drone it waits for has arrived too.
void Engine::arrive(int node) {
  const Node& n = m_.nodes[node];
  if (n.notify >= 0) announce(node);
  if (!n.internal) return;  // a drone without a clone only announces
  state_[node].local_ready = true;
  pass_barrier_when_complete(node);
}

void Engine::pass_barrier_when_complete(int node) {
  State& s = state_[node];
  if (!s.local_ready || s.arrivals_pending > 0) return;
  s.local_ready = m_.nodes[node].exec_in == 0;  // counters ready for the next activation (loops)
  s.arrivals_pending = m_.nodes[node].waits_count;
  activate(node, false);
}

void Engine::announce(int node) {
  const Node& n = m_.nodes[node];
  Message msg{Message::Kind::arrived, m_.hash, m_.self, n.meg, Branch::any};
  msg.sent = loop_.now();
  if (n.scope >= 0) {
    msg.scope = n.scope;
    msg.epoch = epoch_of(n.scope);
  }
  if (hooks_.transport) hooks_.transport->send_to_set(m_.drone_sets[n.notify], msg);
}

void Engine::receive_arrival(int node, const Message& msg) {
  if (halted_ || node < 0 || m_.nodes[node].waits_count == 0) return;  // not a sync point it waits at
  if (!current(msg)) return;
  queue_.push_back({node, ArcKind::exec, false, true});
  drain();
}

void Engine::count_arrival(int node, const Message& msg) {
  if (halted_ || node < 0) return;
  // Outside every Repeat/Do body there are no runs to learn or refresh (current() and
  // refresh() change nothing), and a barrier still waiting has nothing else to do.
  if (msg.scope < 0 && msg.body_epoch == 0 && m_.nodes[node].scope < 0 && !draining_ && queue_.empty()) {
    State& s = state_[node];
    if (m_.nodes[node].waits_count > 0 && (!s.local_ready || s.arrivals_pending > 1)) {
      --s.arrivals_pending;
      return;
    }
  }
  receive_arrival(node, msg);
}

int Engine::add_arrivals(int node, int n) {
  if (node < 0) return 0;
  State& s = state_[node];
  if (!halted_) s.arrivals_pending -= n;
  return s.arrivals_pending;
}

// Learns the runs `msg` names; false when it belongs to a run that is over here (stale).
bool Engine::current(const Message& msg) {
  if (msg.scope >= 0) {
    long long& known = epoch_[msg.scope];
    // A cancel belongs to one iteration; a trigger to its run (see kIterationBits).
    bool stale = msg.kind == Message::Kind::cancel ? msg.epoch < known : run_of(msg.epoch) < run_of(known);
    if (stale) return false;
    known = std::max(known, msg.epoch);
  }
  if (msg.body_epoch > 0) {
    long long& known = epoch_[msg.meg];
    known = std::max(known, msg.body_epoch);
  }
  return true;
}

void Engine::receive(const Message& msg) {
  if (halted_ || msg.mission_hash != m_.hash) return;
  if (msg.kind == Message::Kind::arrived) return receive_arrival(m_.find(msg.meg, m_.self), msg);
  int from = m_.find(msg.meg, msg.from);
  if (from < 0 || !current(msg)) return;
  if (msg.kind == Message::Kind::cancel) {
    cancel_local(m_.nodes[from].cancels);
    drain();  // settles: the cancel may have left this drone idle
    return;
  }
  for (int a : m_.nodes[from].out) {
    const Arc& arc = m_.arcs[a];
    if (arc.branch != Branch::any && arc.branch != msg.branch) continue;
    if (!m_.nodes[arc.to].internal) continue;
    queue_.push_back({arc.to, arc.kind, false});
  }
  drain();
}

void Engine::receive(std::shared_ptr<const Telemetry> t) {
  if (!t || t->mission_hash != m_.hash) return;
  // Telemetry of a drone this mission never reads changes nothing here (no condition or
  // argument reads it): it is not kept.
  int slot = board_slot(t->from);
  if (slot < 0) return;
  int from = t->from;
  board_[slot] = std::move(t);
  properties_changed(from);
}

void Engine::activate(int node, bool by_back_arc) {
  ++activations_;
  const Node& n = m_.nodes[node];
  switch (n.kind) {
    case MegKind::init:
    case MegKind::fork:
    case MegKind::terminal: end(node, Branch::any); return;
    case MegKind::end:
      trace_node(n, "ended", Branch::any);
      if (hooks_.on_end) hooks_.on_end();
      return;
    case MegKind::action: activate_action(node); return;
    case MegKind::pause: activate_pause(node); return;
    case MegKind::condition: activate_condition(node, by_back_arc); return;
  }
}

void Engine::activate_action(int node) {
  const Node& n = m_.nodes[node];
  mid::ActionRequest req;
  req.name = n.name;
  auto read = [this](int d, const std::string& p) { return property(d, p); };
  for (const Expr& a : n.args) req.args.push_back(evaluate(a, read).number);
  if (hooks_.observer) hooks_.observer->action_started(loop_.now(), m_.self, n, req, drone_.state());
  trace(n, "start");
  ++active_;
  // Its own instance: an earlier activation of this node may still run (async work in a
  // loop); both end, each once. The drone never calls on_end inside start().
  std::uint64_t id = ++next_instance_;
  mid::ActionId action =
      drone_.start(req, [this, node, id](const mid::ActionEnd& e) { on_action_end(node, id, e); });
  state_[node].running.push_back({id, action, mid::kNoTimer});
}

void Engine::activate_pause(int node) {
  const Node& n = m_.nodes[node];
  trace_node(n, "started", Branch::any);  // a pause runs for a while, like an action
  ++active_;
  std::uint64_t id = ++next_instance_;
  mid::TimerId timer = loop_.after(n.seconds, [this, node, id] {
    if (!take_instance(node, id)) return;
    --active_;
    end(node, Branch::any);
    drain();
  });
  state_[node].running.push_back({id, mid::kNoAction, timer});
}

/// Removes a running instance of `node`; false when it is no longer running (cancelled).
bool Engine::take_instance(int node, std::uint64_t id) {
  std::vector<Instance>& running = state_[node].running;
  auto it = std::find_if(running.begin(), running.end(), [id](const Instance& i) { return i.id == id; });
  if (it == running.end()) return false;
  running.erase(it);
  return true;
}

void Engine::on_action_end(int node, std::uint64_t instance, const mid::ActionEnd& e) {
  if (!take_instance(node, instance)) return;  // closed when it was cancelled
  const Node& n = m_.nodes[node];
  --active_;
  trace_end(n, e);
  switch (e.outcome) {
    case mid::Outcome::succeeded:
    case mid::Outcome::preempted:
      end(node, Branch::any);
      drain();
      return;
    case mid::Outcome::cancelled:  // cancelled by a Do flip or the failsafe: no successors
      drain();
      return;
    case mid::Outcome::failed:
      if (hooks_.on_failure) hooks_.on_failure({m_.fleet[m_.self], n.name, n.line, e.reason, e.failure, e.detail});
      return;
  }
}

void Engine::trace_end(const Node& n, const mid::ActionEnd& e) {
  if (!hooks_.trace) return;
  TraceEvent t;
  t.t = loop_.now();
  t.drone = m_.fleet[m_.self];
  t.event = "end";
  t.name = n.name;
  t.line = n.line;
  t.col = n.col;
  t.text = n.text;
  t.outcome = mid::outcome_name(e.outcome);
  t.reason = e.reason;
  t.node = n.meg;
  t.failure = mid::failure_reason_name(e.failure);
  t.detail = e.detail;
  hooks_.trace->record(t);
  if (e.value && e.outcome == mid::Outcome::succeeded) {
    t.event = "sensor";
    t.outcome.clear();
    t.reading = e.value;
    hooks_.trace->record(t);
  }
}

bool Engine::condition_value(int node) {
  const Node& n = m_.nodes[node];
  auto read = [this](int d, const std::string& p) { return property(d, p); };
  bool v = evaluate(n.condition, read).boolean;
  if (hooks_.observer) v = hooks_.observer->condition(loop_.now(), m_.self, n, v, read);
  // Watched conditions are re-evaluated at the telemetry rate: trace a value once, then
  // only when it changes, so the trace shows decisions, not samples.
  State& s = state_[node];
  bool changed = s.last_value != static_cast<int>(v);
  s.last_value = s.watchers > 0 ? static_cast<int>(v) : -1;
  if (hooks_.trace && changed) {
    TraceEvent t;
    t.t = loop_.now();
    t.drone = m_.fleet[m_.self];
    t.event = "condition";
    t.name = lang::control_name(n.control);
    t.line = n.line;
    t.col = n.col;
    t.text = n.text;
    t.value = v;
    t.node = n.meg;
    hooks_.trace->record(t);
  }
  return v;
}

void Engine::activate_condition(int node, bool by_back_arc) {
  const Node& n = m_.nodes[node];
  State& s = state_[node];
  switch (n.control) {
    case ControlKind::If: end(node, condition_value(node) ? Branch::true_ : Branch::false_); return;
    case ControlKind::WaitUntil:
    case ControlKind::WaitWhile:
    case ControlKind::PauseUntil:
    case ControlKind::PauseWhile:
      ++active_;
      if (s.watchers++ == 0) watch(node);
      evaluate_watch(node);
      return;
    case ControlKind::RepeatUntil:
    case ControlKind::RepeatWhile:
    case ControlKind::RepeatFor: activate_repeat(node, by_back_arc); return;
    case ControlKind::DoUntilSync:
    case ControlKind::DoWhileSync:
    case ControlKind::DoUntilAsync:
    case ControlKind::DoWhileAsync: activate_do(node); return;
    default: end(node, Branch::any); return;
  }
}

void Engine::activate_repeat(int node, bool by_back_arc) {
  const Node& n = m_.nodes[node];
  State& s = state_[node];
  if (!by_back_arc) {
    s.iterations = 0;
    s.instant_iterations = 0;
    epoch_[n.meg] = next_run(epoch_[n.meg]);  // a new run of the loop
  }
  s.iteration_started = loop_.now();
  bool v = condition_value(node);
  bool again = n.control == ControlKind::RepeatUntil ? !v
               : n.control == ControlKind::RepeatWhile ? v
                                                       : v && s.iterations < n.count;
  if (again) {
    ++s.iterations;
    ++epoch_[n.meg];  // a new iteration of the repeat branch
  }
  end(node, again ? Branch::repeat : Branch::exit);
}

// Wait* and Pause*: "go" once the awaited state holds (Until: true, While: false).
void Engine::evaluate_watch(int node) {
  const Node& n = m_.nodes[node];
  bool v = condition_value(node);
  bool until = n.control == ControlKind::WaitUntil || n.control == ControlKind::PauseUntil;
  if (v == until) {
    int waiting = state_[node].watchers;
    stop_watching(node);
    for (int i = 0; i < waiting; ++i) end(node, Branch::go);  // each activation goes on
  }
}

void Engine::properties_changed(int drone) {
  if (halted_ || watched_.empty()) return;
  std::vector<int> now = watched_;  // ending a watch edits watched_
  for (int node : now) {
    if (state_[node].watchers == 0) continue;
    const Node& n = m_.nodes[node];
    const std::vector<int>& reads = n.condition_reads;
    if (std::find(reads.begin(), reads.end(), drone) == reads.end()) continue;
    if (is_do(n.control)) recheck_do(node);
    else evaluate_watch(node);
  }
  drain();
}

void Engine::stop_watching(int node) {
  State& s = state_[node];
  if (s.watchers == 0) return;
  active_ -= s.watchers;
  s.watchers = 0;
  s.last_value = -1;
  unwatch(node);
}

void Engine::watch(int node) {
  watched_.push_back(node);
  if (hooks_.watching) *hooks_.watching = true;
}

void Engine::unwatch(int node) {
  watched_.erase(std::remove(watched_.begin(), watched_.end(), node), watched_.end());
  if (hooks_.watching) *hooks_.watching = !watched_.empty();
}

void Engine::unwatch_all() {
  watched_.clear();
  if (hooks_.watching) *hooks_.watching = false;
}

void Engine::cancel_local(const std::vector<int>& nodes) {
  for (int node : nodes) {
    State& s = state_[node];
    const Node& n = m_.nodes[node];
    // A cancelled action is over for the mission now, not when the drone's end callback
    // comes: its end is traced here, in the order the cancel arrived (the same order on
    // every transport), and the callback, when it comes, is ignored.
    // An action the drone could not cancel has ended already: its end callback is on its
    // way and stands.
    std::vector<Instance> still;
    for (const Instance& i : s.running) {
      if (i.timer != mid::kNoTimer) {
        loop_.cancel(i.timer);
        --active_;
      } else if (drone_.cancel(i.action)) {
        --active_;
        trace_end(n, {mid::Outcome::cancelled, "cancelled", std::nullopt});
      } else {
        still.push_back(i);
      }
    }
    s.running = std::move(still);
    if (s.next_iteration != mid::kNoTimer) {
      loop_.cancel(s.next_iteration);
      s.next_iteration = mid::kNoTimer;
      --active_;
    }
    stop_watching(node);
    reset_counters(node);
  }
  // Triggers already queued for cancelled nodes must not start them.
  queue_.erase(std::remove_if(queue_.begin(), queue_.end(),
                              [&](const Delivery& d) {
                                return std::find(nodes.begin(), nodes.end(), d.node) != nodes.end();
                              }),
               queue_.end());
}

void Engine::trace_node(const Node& n, const char* outcome, Branch branch) {
  if (!hooks_.trace || n.kind == MegKind::action) return;  // actions have start and end events
  TraceEvent e;
  e.t = loop_.now();
  e.drone = m_.fleet[m_.self];
  e.event = "node";
  e.kind = graph::meg_kind_name(n.kind);
  e.name = n.kind == MegKind::condition ? lang::control_name(n.control) : n.name;
  e.line = n.line;
  e.col = n.col;
  e.outcome = outcome;
  e.branch = branch == Branch::any ? "" : graph::branch_name(branch);
  e.node = n.meg;
  if (graph::is_sync_point(n.kind)) e.instance = m_.self;
  hooks_.trace->record(e);
}

void Engine::end(int node, Branch branch, bool released_by_partner, bool released) {
  const Node& n = m_.nodes[node];
  trace_node(n, released ? "released" : "ended", branch);
  std::vector<int> remote;
  for (int a : n.out) {
    const Arc& arc = m_.arcs[a];
    if (arc.branch != Branch::any && arc.branch != branch) continue;
    if (released_by_partner && arc.kind == ArcKind::partner) continue;
    // A sync point counts this drone's own arcs into it, on every drone (dex::Engine::arrive).
    if (m_.nodes[arc.to].internal || graph::is_sync_point(m_.nodes[arc.to].kind)) {
      queue_.push_back({arc.to, arc.kind, n.kind == MegKind::terminal});
    } else if (std::find(remote.begin(), remote.end(), m_.nodes[arc.to].drone) == remote.end()) {
      remote.push_back(m_.nodes[arc.to].drone);
    }
  }
  Message msg{Message::Kind::ended, m_.hash, m_.self, n.meg, branch};
  msg.sent = loop_.now();
  if (n.scope >= 0) {
    msg.scope = n.scope;
    msg.epoch = epoch_of(n.scope);
  }
  if (n.kind == MegKind::condition) msg.body_epoch = epoch_of(n.meg);
  for (int d : remote)
    if (hooks_.transport) hooks_.transport->send(d, msg);
}

void Engine::halt() {
  halted_ = true;
  queue_.clear();
  for (std::size_t i = 0; i < state_.size(); ++i) {
    State& s = state_[i];
    // Cancelled actions stay listed: their ends, when the drone reports them, are traced.
    for (const Instance& r : s.running) {
      if (r.timer != mid::kNoTimer) loop_.cancel(r.timer);
      else drone_.cancel(r.action);
    }
    loop_.cancel(s.next_iteration);
    s.next_iteration = mid::kNoTimer;
    s.watchers = 0;
  }
  unwatch_all();
}

}  // namespace eamos::dex
