#pragma once
// Execution events as the DEX reports them: the run's trace (JSON Lines) and its live log
// are both made from these.
#include <optional>
#include <string>

namespace eamos::dex {

struct TraceEvent {
  double t = 0.0;           ///< mission seconds
  std::string drone;
  std::string event;        ///< start | end | condition | sensor | failsafe | error | vehicle (its own words)
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
};

class TraceSink {
 public:
  virtual ~TraceSink() = default;
  virtual void record(const TraceEvent& e) = 0;
};

}  // namespace eamos::dex
