#pragma once
// The mission's geofence given to the autopilot's own fence (fleet `geofence: {upload: true}`),
// so that the vehicle holds it even when the companion computer running eamos fails. At
// connect, before Arm: the polygon goes up with the mission protocol (mission_type FENCE,
// one MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION per corner), is read back and compared, then
// the fence is switched on with parameters (ArduPilot FENCE_*, PX4 GF_*), each confirmed by
// the PARAM_VALUE the autopilot answers. Every wait is in mission time and retried; what the
// vehicle refuses, or never answers, ends the upload with the reason, which Arm then fails with.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "fleet/fleet.h"
#include "mavlink/payloads.h"
#include "mavlink_adapter/autopilot.h"
#include "mid/event_loop.h"

namespace eamos::mavlink_adapter {

/// One parameter that switches the fence on. `integer`: the autopilot keeps it as an integer
/// (PX4 then reads param_value's bytes as an int32: MAVLink's bytewise encoding).
struct FenceParam {
  std::string name;
  float value = 0;
  bool integer = true;
};

/// The fence as the autopilot takes it.
struct AutopilotFence {
  std::vector<mavlink::MissionItemInt> items;  ///< seq 0…n-1, mission_type FENCE
  std::vector<FenceParam> params;              ///< in the order they are set; the switch last
};

/// Where the vehicle's local NED origin lies on the earth (degE7): mission-frame corners are
/// placed from it as the adapter places its setpoints (mission = home + NED east/north).
struct GlobalOrigin {
  int32_t lat_e7 = 0, lon_e7 = 0;
};

/// The polygon of `g` as fence items for system `sysid`, and the parameters that make `a`
/// hold it: its ceiling is `max_altitude` less `home.z` (the autopilots count from home); a
/// breach does what the drone's failsafe does (land, return home, hold).
AutopilotFence autopilot_fence(const Autopilot& a, const fleet::Geofence& g, fleet::Vec3 home,
                               fleet::Failsafe failsafe, GlobalOrigin origin, uint8_t sysid);

/// "" when `read` (what the vehicle sent back) is `sent`'s polygon, else the first difference.
/// A corner may differ by 1e-7 degree (a centimetre): an autopilot may store it as a double.
std::string compare_fence(const std::vector<mavlink::MissionItemInt>& sent,
                          const std::vector<mavlink::MissionItemInt>& read);

/// MAV_MISSION_RESULT in words, for a refusal.
std::string mission_result_text(uint8_t result);

class FenceUpload {
 public:
  struct Hooks {
    std::function<void(const mavlink::Message&)> send;
    std::function<void(const std::string&)> note;  ///< progress worth a trace line
  };
  struct Options {
    double reply_timeout_s = 1.0;  ///< mission seconds to wait for each answer before resending
    int attempts = 5;              ///< sends of one message before the vehicle counts as silent
  };
  using Done = std::function<void(const std::string& error)>;

  FenceUpload(mid::EventLoop& loop, const Autopilot& autopilot, Hooks hooks, Options options);
  ~FenceUpload();
  FenceUpload(const FenceUpload&) = delete;
  FenceUpload& operator=(const FenceUpload&) = delete;

  /// Uploads `fence` to system `sysid`'s autopilot; `done` runs once with "" or the reason.
  void start(AutopilotFence fence, uint8_t sysid, Done done);
  /// A message of the vehicle's autopilot (component 1).
  void on_message(const mavlink::Message& m);

  bool finished() const { return phase_ == Phase::done; }
  const std::string& error() const { return error_; }  ///< why it failed; "" while fine

 private:
  enum class Phase { idle, upload, read_count, read_items, params, done };
  void on_request(const mavlink::MissionRequest& r);
  void on_ack(const mavlink::MissionAck& a);
  void on_count(const mavlink::MissionCount& c);
  void on_item(const mavlink::MissionItemInt& item);
  void on_param(const mavlink::ParamValue& v);
  void read_back();
  void request_item(uint16_t seq);
  void set_param();
  /// Sends `m` now and again every reply_timeout_s until the next expect(); after `attempts`
  /// sends the vehicle is silent and the upload fails, saying `waiting_for`.
  void expect(mavlink::Message m, std::string waiting_for);
  void resend();
  void finish(const std::string& error);
  mavlink::MissionItemInt addressed(mavlink::MissionItemInt item) const;

  mid::EventLoop& loop_;
  const Autopilot& autopilot_;
  Hooks hooks_;
  Options options_;
  Phase phase_ = Phase::idle;
  AutopilotFence fence_;
  uint8_t sysid_ = 0;
  Done done_;
  std::string error_;
  std::vector<mavlink::MissionItemInt> read_;  ///< the read-back items so far
  uint16_t read_count_ = 0;
  std::size_t param_ = 0;                      ///< the parameter being set
  mavlink::Message pending_;                   ///< what resend() sends
  std::string waiting_for_;
  int sends_ = 0;
  mid::TimerId timer_ = mid::kNoTimer;
};

}  // namespace eamos::mavlink_adapter
