#pragma once
// Why a mission failed, as the engine reports it and as a drone's final status carries it
// between processes (src/transport): a header of its own, so the transport sees it without
// the engine.
#include <string>

#include "mid/drone_api.h"

namespace eamos::dex {

/// Why a mission failed: the drone, the action and the source line.
struct Failure {
  std::string drone;
  std::string action;  ///< "" for a fault of the drone itself that no action carried
  int line = 0;
  std::string reason;
  mid::FailureReason kind = mid::FailureReason::none;  ///< none: not an action's failure
  std::string detail;  ///< the vehicle's own words (MAV_RESULT, STATUSTEXT), or ""
};

/// "Drone1.FlyTo (line 4) failed: why"; a fault of the drone outside any action (action "")
/// is its reason alone, which names the drone.
inline std::string failure_text(const Failure& f) {
  if (f.action.empty()) return f.reason;
  return f.drone + "." + f.action + " (line " + std::to_string(f.line) + ") failed: " + f.reason;
}

}  // namespace eamos::dex
