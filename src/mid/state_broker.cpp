#include "mid/state_broker.h"

#include <vector>

namespace eamos::mid {

SubscriptionId StateBroker::subscribe(StateCallback fn) {
  SubscriptionId id = next_id_++;
  subscribers_.emplace(id, std::move(fn));
  return id;
}

void StateBroker::unsubscribe(SubscriptionId id) { subscribers_.erase(id); }

void StateBroker::publish(const DroneState& state) {
  // Walk a snapshot of the ids: a callback may change the map under us.
  std::vector<SubscriptionId> ids;
  ids.reserve(subscribers_.size());
  for (const auto& [id, fn] : subscribers_) ids.push_back(id);
  for (SubscriptionId id : ids) {
    auto it = subscribers_.find(id);
    if (it == subscribers_.end()) continue;
    StateCallback fn = it->second;  // a copy: the callback may unsubscribe itself
    fn(state);
  }
}

}  // namespace eamos::mid
