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

}  // namespace eamos::mid
