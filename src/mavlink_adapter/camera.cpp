#include "mavlink_adapter/camera.h"

#include <algorithm>
#include <array>
#include <cstdio>

#include "mavlink/enums.h"

namespace eamos::mavlink_adapter {

namespace ml = eamos::mavlink;
using mid::ActionId;

void Camera::take(ActionId id) {
  const Autopilot& ap = *link_.autopilot();
  std::array<float, 7> p{};
  if (ap.picture_command == ml::cmd::DO_DIGICAM_CONTROL) p[4] = 1;  // param5: shoot once
  else p[2] = 1;                                                     // param3: one image
  pending_[id] = {};
  commands_.send(link_.command(ap.picture_command, p), [this, id](const CommandResult& result) { acked(id, result); });
}

void Camera::acked(ActionId id, const CommandResult& result) {
  auto it = pending_.find(id);
  if (!hooks_.running(id) || it == pending_.end()) return;
  if (!result.accepted) {
    pending_.erase(it);
    auto why = result.answered ? mid::FailureReason::refused : mid::FailureReason::timed_out;
    hooks_.failed(id, why, "no picture: " + result.error, result.error);
    return;
  }
  it->second.acked = true;
  if (it->second.confirmed) return end(id);  // the camera spoke before the ACK
  hooks_.after(id, confirm_s_, [this, id] { unconfirmed(id); });
}

void Camera::unconfirmed(ActionId id) {
  const Autopilot& ap = *link_.autopilot();
  pending_.erase(id);
  char text[256];
  std::snprintf(text, sizeof text,
                "no picture: %s accepted %s but no camera confirmed a picture (CAMERA_TRIGGER, "
                "CAMERA_FEEDBACK or CAMERA_IMAGE_CAPTURED) within %.1f s; is a camera configured "
                "(ArduPilot CAM1_TYPE, PX4 TRIG_MODE and TRIG_INTERFACE)?",
                ap.name, ml::command_name(ap.picture_command).c_str(), confirm_s_);
  if (hooks_.running(id)) hooks_.failed(id, mid::FailureReason::timed_out, text, "");
}

// A confirmation nobody waits for (a ground station's, a survey's trigger) is only noted.
void Camera::on_capture(const ml::CameraCapture& c) {
  auto it = std::find_if(pending_.begin(), pending_.end(), [](const auto& p) { return !p.second.confirmed; });
  const char* what = c.message_id == ml::msg::CAMERA_TRIGGER    ? "CAMERA_TRIGGER"
                     : c.message_id == ml::msg::CAMERA_FEEDBACK ? "CAMERA_FEEDBACK"
                                                                : "CAMERA_IMAGE_CAPTURED";
  hooks_.note(std::string(link_.autopilot()->name) + " camera: " + (c.captured ? "took" : "failed to take") +
              " image " + std::to_string(c.image_index) + " (" + what + ")");
  // PX4 reports one image twice (CAMERA_TRIGGER, then CAMERA_IMAGE_CAPTURED, same number):
  // the second must not confirm the next picture before its camera has taken it.
  if (last_image_index_ == c.image_index) return;
  if (it == pending_.end()) return;
  last_image_index_ = c.image_index;
  ActionId id = it->first;
  if (!c.captured) {
    hooks_.clear_timer(id);
    pending_.erase(it);
    hooks_.failed(id, mid::FailureReason::vehicle_fault,
                  std::string("no picture: the camera reported a failed capture (") + what + ")", what);
    return;
  }
  it->second.confirmed = true;
  if (it->second.acked) end(id);
}

void Camera::end(ActionId id) {
  hooks_.clear_timer(id);
  pending_.erase(id);
  ++pictures_;
  hooks_.taken(id);
}

}  // namespace eamos::mavlink_adapter
