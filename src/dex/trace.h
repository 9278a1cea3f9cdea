#pragma once
// Execution events as the DEX reports them: the run's trace (JSON Lines) and its live log
// are both made from these.
#include <optional>
#include <string>

#include "mid/drone_api.h"

namespace eamos::dex {

struct TraceEvent {
  double t = 0.0;           ///< mission seconds
  std::string drone;
  std::string event;        ///< start | end | condition | sensor | node | failsafe | error | vehicle (its own words) | telemetry | message | mission | conflict | give_way | resume
  std::string name;         ///< action or control structure
  int line = 0;
  std::string text;         ///< "Drone1.Takeoff(3)", "Drone1.Sensor1() >= 100"
  std::string outcome;      ///< end: succeeded | preempted | cancelled | failed
  std::optional<bool> value;      ///< condition
  std::optional<double> reading;  ///< sensor
  std::string reason;       ///< end failed / preempted: why
  std::string failure;      ///< end failed: the uniform kind (mid::failure_reason_name), else ""
  std::string detail;       ///< end failed: the vehicle's own words (MAV_RESULT, STATUSTEXT), or ""
  int col = 0;              ///< source column of `name` (0 when unknown); not in the JSONL trace
  int node = -1;            ///< MEG node id of the node the event is about; -1 none
  std::string branch;       ///< event "node": the branch a condition released (go, true, repeat, …)
  int instance = -1;        ///< a cloned sync point (init, fork, end): the drone holding the clone; -1 none
  // event "message": a trigger or cancel that crossed from one drone to another.
  std::string kind;         ///< message: trigger | cancel | finished | abort; node: init | fork | terminal | end | pause | condition
  int from = -1;            ///< sender (drone index; -1 the ground)
  int to = -1;              ///< receiver (drone index; -1 every drone)
  double sent = 0.0;        ///< the sender's mission time when it sent it (t: when it arrived)
  // events "conflict", "give_way", "resume" (dex/separation.h): the other drone of the
  // pair and how far apart the two are now (m, straight line).
  std::string other;
  std::optional<double> distance;
  // event "telemetry": the drone's state at t.
  std::optional<mid::DroneState> state;
};

/// conflict, give_way and resume (dex/separation.h): `other` names the other drone, `to`
/// holds its index (how it crosses DDS) and `distance` how far apart the two are.
inline bool is_separation_event(const std::string& event) {
  return event == "conflict" || event == "give_way" || event == "resume";
}

class TraceSink {
 public:
  virtual ~TraceSink() = default;
  virtual void record(const TraceEvent& e) = 0;
  /// Whether this sink keeps `message` events: in one process a fleet-wide barrier of k
  /// drones is k² of them, built only when someone keeps them.
  virtual bool takes_messages() const { return true; }
};

}  // namespace eamos::dex
