#pragma once
// A property broker (paper, section VI): hands a drone's newest state to whoever subscribed.
// Adapters own one and decide when to publish (telemetry rate, state changes); the broker
// only keeps the subscribers and calls them in subscription order.
#include <map>

#include "mid/drone_api.h"

namespace eamos::mid {

class StateBroker {
 public:
  SubscriptionId subscribe(StateCallback fn);
  void unsubscribe(SubscriptionId id);
  bool empty() const { return subscribers_.empty(); }
  /// Calls every subscriber; one may unsubscribe itself or others while being called.
  void publish(const DroneState& state);

 private:
  SubscriptionId next_id_ = 1;
  std::map<SubscriptionId, StateCallback> subscribers_;
};

}  // namespace eamos::mid
