#pragma once
// The wire to one vehicle: connecting to it (its first HEARTBEAT picks the autopilot row,
// MAVLink 2 signing is set up, its speed parameters are read), our own HEARTBEAT at 1 Hz,
// frames out, and who the vehicle is. Frames in arrive on the link's thread and are posted
// to the event loop, so the frame handler runs on the loop's thread only.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "fleet/fleet.h"
#include "mavlink/link.h"
#include "mavlink_adapter/autopilot.h"
#include "mavlink_adapter/autopilot_params.h"
#include "mavlink_adapter/mavlink_options.h"
#include "mid/event_loop.h"

namespace eamos::mavlink_adapter {

struct FirstHeartbeat;  ///< vehicle_link.cpp

class VehicleLink {
 public:
  using FrameHandler = std::function<void(const mavlink::Frame&)>;
  using Note = std::function<void(const std::string&)>;
  VehicleLink(const fleet::DroneSettings& settings, mid::EventLoop& loop, const MavlinkOptions& options,
              FrameHandler on_frame, Note note);
  ~VehicleLink();
  VehicleLink(const VehicleLink&) = delete;
  VehicleLink& operator=(const VehicleLink&) = delete;

  /// Opens the link and waits (blocking, up to connect_timeout_s) for the vehicle's first
  /// HEARTBEAT; "" on success, else what went wrong and what to check. On success our own
  /// HEARTBEAT has started.
  std::string connect(const fleet::Endpoint& endpoint);
  /// Joins the receive thread: no frame is posted after it. Says how many datagrams from
  /// other addresses were ignored, if any.
  void close();

  void send(const mavlink::Message& m);
  /// A COMMAND_LONG to the vehicle's autopilot.
  mavlink::CommandLong command(uint16_t id, std::array<float, 7> params = {}) const;

  uint8_t sysid() const { return sysid_; }  ///< the vehicle's system id (0 until connected)
  /// The autopilot row chosen from the first HEARTBEAT; nullptr before connect().
  const Autopilot* autopilot() const { return autopilot_; }
  /// The slower of the fleet's and the autopilot's limits (known after connect()).
  const FlightLimits& limits() const { return limits_; }

  /// A frame of the vehicle refused for its values: counted and logged, never applied.
  void note_rejected(const char* what);
  /// Datagrams the udp:// link dropped for coming from another address than the vehicle's:
  /// logged (the first, then every thousandth) and the first one put in the trace.
  void note_foreign();

 private:
  /// Runs on the link's thread: notes the first HEARTBEAT and parameters, posts the frame.
  std::function<void(mavlink::Frame)> receiver(std::shared_ptr<FirstHeartbeat> first, uint8_t wanted);
  std::string no_heartbeat(const fleet::Endpoint& endpoint, uint8_t wanted, bool signing) const;
  /// After the first HEARTBEAT: the autopilot row, signing, the speed parameters.
  std::string identify(FirstHeartbeat& first, std::unique_lock<std::mutex>& lock,
                       const fleet::Endpoint& endpoint, const std::optional<mavlink::SigningKey>& key);
  /// fleet `signing: {setup: true}`: gives the vehicle the key at connect.
  std::string give_key(FirstHeartbeat& first, std::unique_lock<std::mutex>& lock, const mavlink::SigningKey& key);
  void read_limits(FirstHeartbeat& first, std::unique_lock<std::mutex>& lock);
  void send_heartbeat();

  const fleet::DroneSettings& settings_;
  mid::EventLoop& loop_;
  const MavlinkOptions& options_;
  FrameHandler on_frame_;
  Note note_;
  const Autopilot* autopilot_ = nullptr;
  uint8_t sysid_ = 0;
  FlightLimits limits_;
  uint64_t rejected_frames_ = 0;  ///< frames of the vehicle refused for their values
  uint64_t foreign_reported_ = 0; ///< link's foreign_datagrams() when last looked at
  /// Posted frames hold a weak pointer to this: a frame that reaches the loop after the
  /// drone is gone is dropped instead of touching freed memory.
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
  std::unique_ptr<mavlink::Link> link_;
  mavlink::Encoder encoder_;
  mid::TimerId heartbeat_timer_ = mid::kNoTimer;
};

}  // namespace eamos::mavlink_adapter
