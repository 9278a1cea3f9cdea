#pragma once
// TakePicture: ArduPilot MAV_CMD_IMAGE_START_CAPTURE, PX4 MAV_CMD_DO_DIGICAM_CONTROL. A
// picture counts once the vehicle confirms it (CAMERA_TRIGGER, CAMERA_FEEDBACK or
// CAMERA_IMAGE_CAPTURED), not at the COMMAND_ACK: an autopilot accepts the command with no
// camera behind it. Each confirmation goes to the oldest picture still waiting for one.
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "mavlink_adapter/command_sender.h"
#include "mavlink_adapter/vehicle_link.h"
#include "mid/drone_api.h"

namespace eamos::mavlink_adapter {

class Camera {
 public:
  /// What the camera may do to the TakePicture actions it serves.
  struct Hooks {
    std::function<bool(mid::ActionId)> running;
    std::function<void(mid::ActionId)> taken;  ///< ends it `succeeded`
    std::function<void(mid::ActionId, mid::FailureReason, const std::string& reason, const std::string& detail)>
        failed;
    /// Runs the function after the delay while the action runs (AdapterDrone::after_for).
    std::function<void(mid::ActionId, double, std::function<void()>)> after;
    std::function<void(mid::ActionId)> clear_timer;
    std::function<void(const std::string&)> note;  ///< to the trace
  };
  Camera(VehicleLink& link, CommandSender& commands, double confirm_s, Hooks hooks)
      : link_(link), commands_(commands), confirm_s_(confirm_s), hooks_(std::move(hooks)) {}

  void take(mid::ActionId id);
  /// CAMERA_TRIGGER, CAMERA_FEEDBACK or CAMERA_IMAGE_CAPTURED from the vehicle.
  void on_capture(const mavlink::CameraCapture& c);
  /// The picture `id` is no longer waited for (cancelled, failsafe).
  void forget(mid::ActionId id) { pending_.erase(id); }
  void forget_all() { pending_.clear(); }
  int pictures() const { return pictures_; }  ///< confirmed so far

 private:
  struct Picture {
    bool acked = false;      ///< the autopilot accepted the command
    bool confirmed = false;  ///< the camera said it took one
  };
  void acked(mid::ActionId id, const CommandResult& result);
  void unconfirmed(mid::ActionId id);
  void end(mid::ActionId id);  ///< acknowledged and confirmed: taken

  VehicleLink& link_;
  CommandSender& commands_;
  double confirm_s_;  ///< how long after the ACK to wait for the camera (mission s)
  Hooks hooks_;
  int pictures_ = 0;
  std::map<mid::ActionId, Picture> pending_;  ///< oldest first (ids grow)
  std::optional<int64_t> last_image_index_;   ///< the image that confirmed the last picture
};

}  // namespace eamos::mavlink_adapter
