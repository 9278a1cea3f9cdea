// The Do family in the engine (engine_do.h). A Do condition whose value says "do" starts
// one run of its do-branch and watches the condition while it runs; the run ends by itself
// (its do-terminal's `stop` arc ends the watch, engine.cpp) or by a flip: the condition
// no longer says "do", the run is cancelled on every drone it spans and the done-branch
// starts. Each run is an epoch of the body (epoch.h), so nothing from a cancelled run
// starts anything in the next one.
#include "dex/engine.h"
#include "dex/engine_do.h"
#include "dex/epoch.h"

namespace eamos::dex {

using graph::Branch;

void Engine::activate_do(int node) {
  const Node& n = m_.nodes[node];
  State& s = state_[node];
  // Started again while its do-branch still runs (a Do*Async in a loop): one condition,
  // one run; the earlier run is cancelled on every drone, without its done-branch.
  if (s.watchers > 0) {
    stop_watching(node);
    cancel_do_run(node);
  }
  bool v = condition_value(node);
  if (says_do(n.control, v)) {
    s.watchers = 1;
    s.last_value = static_cast<int>(v);  // traced just now: log again only on a change
    ++active_;
    watch(node);
    epoch_[n.meg] = next_run(epoch_[n.meg]);  // a new run of the do-branch
    end(node, Branch::do_);
  } else {
    end(node, Branch::skip);
  }
  if (is_async_do(n.control)) end(node, Branch::continue_);
}

void Engine::recheck_do(int node) {
  if (!says_do(m_.nodes[node].control, condition_value(node))) flip_do(node);
}

void Engine::flip_do(int node) {
  stop_watching(node);
  cancel_do_run(node);
  end(node, Branch::done);
}

void Engine::cancel_do_run(int node) {
  const Node& n = m_.nodes[node];
  epoch_[n.meg] = next_run(epoch_[n.meg]);  // the cancelled run is over: anything still in flight from it is stale
  cancel_local(n.cancels);
  Message msg{Message::Kind::cancel, m_.hash, m_.self, n.meg, Branch::any};
  msg.body_epoch = epoch_[n.meg];
  msg.sent = loop_.now();
  if (n.scope >= 0) {
    msg.scope = n.scope;
    msg.epoch = epoch_of(n.scope);
  }
  for (int d = 0; d < static_cast<int>(m_.fleet.size()); ++d)
    if (d != m_.self && hooks_.transport) hooks_.transport->send(d, msg);
}

}  // namespace eamos::dex
