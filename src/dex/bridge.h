#pragma once
// What crosses drone boundaries (paper, section V): when an internal node ends, the
// OutBridge tells every drone holding a node it links to; the InBridge of that drone
// applies the links of its external copy of the node. A drone that reaches a sync point
// announces it once to every drone holding a clone, which counts the arrivals it needs.
// A Do condition's flip is broadcast so every drone cancels its part of the do-branch.
#include <vector>
#include <memory>
#include <string>

#include "vocab/kinds.h"
#include "mid/drone_api.h"

namespace eamos::dex {

struct Message {
  enum class Kind {
    ended,   ///< node `meg` held by `from` ended with `branch`
    cancel,  ///< Do condition `meg` held by `from` flipped: cancel its do-branch
    arrived, ///< `from` reached sync point `meg`: its own arcs into it have all fired
  };
  Kind kind = Kind::ended;
  std::string mission_hash;  ///< receivers ignore messages of another mission
  int from = 0;              ///< sending drone
  int meg = 0;               ///< MEG id of the node that ended / flipped
  graph::Branch branch = graph::Branch::any;
  /// Which run of a Repeat/Do body the sender belongs to: `scope` is the MEG id of the
  /// sender's innermost body condition (-1: none) and `epoch` the sender's count of that
  /// body's runs. A receiver that already knows a later run drops the message as stale.
  int scope = -1;
  long long epoch = 0;
  /// Sent by a Repeat/Do condition (and with `cancel`): the run number of its own body.
  long long body_epoch = 0;
  double sent = 0.0;  ///< the sender's mission time when it sent this: for the trace only
};

/// A drone's newest properties, published to every other drone: the argument data and
/// condition inputs of the mission (`Drone3.FlyByX(Drone1.X())` reads Drone1's telemetry).
struct Telemetry {
  std::string mission_hash;
  int from = 0;
  mid::DroneState state;
};

/// The transport under InBridge and OutBridge: in-process here; DDS between processes.
class Transport {
 public:
  virtual ~Transport() = default;
  /// Delivers `m` to drone `to` later (never inside send), in send order per sender.
  virtual void send(int to, const Message& m) = 0;
  /// Delivers `m` to every drone of `to` but its sender, as `send` does. Over DDS one
  /// sample reaches them all; the default sends one message each. `to` is a set of the
  /// mission (Mission::drone_sets) and outlives the delivery.
  virtual void send_to_set(const std::vector<int>& to, const Message& m) {
    for (int d : to)
      if (d != m.from) send(d, m);
  }
  /// Delivers `t` to every other drone later, newest value wins. Shared, not copied: a
  /// drone publishes at 20 Hz to every other drone.
  virtual void publish(std::shared_ptr<const Telemetry> t) = 0;
};

}  // namespace eamos::dex
