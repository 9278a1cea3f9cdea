#include "mid/drone_api.h"

namespace eamos::mid {

const char* outcome_name(Outcome o) {
  switch (o) {
    case Outcome::succeeded: return "succeeded";
    case Outcome::preempted: return "preempted";
    case Outcome::cancelled: return "cancelled";
    case Outcome::failed: return "failed";
  }
  return "failed";
}

const char* failure_reason_name(FailureReason r) {
  switch (r) {
    case FailureReason::none: return "";
    case FailureReason::refused: return "refused";
    case FailureReason::timed_out: return "timed_out";
    case FailureReason::link_lost: return "link_lost";
    case FailureReason::vehicle_fault: return "vehicle_fault";
    case FailureReason::pilot_took_over: return "pilot_took_over";
  }
  return "";
}

}  // namespace eamos::mid
