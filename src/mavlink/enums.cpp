#include "mavlink/enums.h"

namespace eamos::mavlink {

std::string result_text(uint8_t r) {
  switch (r) {
    case result::ACCEPTED: return "MAV_RESULT_ACCEPTED (accepted)";
    case result::TEMPORARILY_REJECTED:
      return "MAV_RESULT_TEMPORARILY_REJECTED (not possible now, e.g. not ready or wrong mode)";
    case result::DENIED: return "MAV_RESULT_DENIED (denied by the autopilot)";
    case result::UNSUPPORTED: return "MAV_RESULT_UNSUPPORTED (the autopilot does not know the command)";
    case result::FAILED: return "MAV_RESULT_FAILED (accepted but failed while executing)";
    case result::IN_PROGRESS: return "MAV_RESULT_IN_PROGRESS (still running)";
    case result::CANCELLED: return "MAV_RESULT_CANCELLED (cancelled)";
  }
  return "MAV_RESULT " + std::to_string(r);
}

std::string command_name(uint16_t c) {
  switch (c) {
    case cmd::NAV_RETURN_TO_LAUNCH: return "MAV_CMD_NAV_RETURN_TO_LAUNCH";
    case cmd::NAV_LAND: return "MAV_CMD_NAV_LAND";
    case cmd::NAV_TAKEOFF: return "MAV_CMD_NAV_TAKEOFF";
    case cmd::DO_ORBIT: return "MAV_CMD_DO_ORBIT";
    case cmd::DO_SET_MODE: return "MAV_CMD_DO_SET_MODE";
    case cmd::COMPONENT_ARM_DISARM: return "MAV_CMD_COMPONENT_ARM_DISARM";
    case cmd::SET_MESSAGE_INTERVAL: return "MAV_CMD_SET_MESSAGE_INTERVAL";
    case cmd::IMAGE_START_CAPTURE: return "MAV_CMD_IMAGE_START_CAPTURE";
    case cmd::DO_DIGICAM_CONTROL: return "MAV_CMD_DO_DIGICAM_CONTROL";
  }
  return "MAV_CMD " + std::to_string(c);
}

}  // namespace eamos::mavlink
