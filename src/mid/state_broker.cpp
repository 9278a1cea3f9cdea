#include "mid/state_broker.h"

namespace eamos::mid {

SubscriptionId StateBroker::subscribe(StateCallback fn) {
  SubscriptionId id = next_id_++;
  subscribers_.emplace(id, std::move(fn));
  return id;
}

void StateBroker::unsubscribe(SubscriptionId id) { subscribers_.erase(id); }

void StateBroker::publish(const DroneState& state) {
  // A callback may change the map under us: the next one is looked up after each call, and
  // one subscribed meanwhile (a later id) is not called this time. No copy of the ids: a
  // simulated drone publishes twenty times a second.
  const SubscriptionId last = next_id_ - 1;
  for (auto it = subscribers_.begin(); it != subscribers_.end() && it->first <= last;) {
    const SubscriptionId id = it->first;
    StateCallback fn = it->second;  // a copy: the callback may unsubscribe itself
    fn(state);
    it = subscribers_.upper_bound(id);
  }
}

}  // namespace eamos::mid
