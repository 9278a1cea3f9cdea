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
  std::string action;
  int line = 0;
  std::string reason;
  mid::FailureReason kind = mid::FailureReason::none;  ///< none: not an action's failure
  std::string detail;  ///< the vehicle's own words (MAV_RESULT, STATUSTEXT), or ""
};

}  // namespace eamos::dex
