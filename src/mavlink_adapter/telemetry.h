#pragma once
// What the adapter knows about its vehicle, from the telemetry it streams, and the mapping
// between the autopilot's local NED frame and the mission frame. The vehicle's local origin
// is where its estimator started (for a vehicle that boots where it takes off: its home), so
//   mission = home + (NED east, NED north, -NED down),
// with `home` the drone's home from the fleet file.
#include <cstdint>
#include <limits>

#include "fleet/fleet.h"
#include "mavlink/frame.h"

namespace eamos::mavlink_adapter {

struct VehicleState {
  bool heard = false;             ///< a HEARTBEAT arrived
  uint8_t autopilot = 0;          ///< MAV_AUTOPILOT of the HEARTBEAT
  uint32_t custom_mode = 0;       ///< the autopilot's flight mode
  bool armed = false;
  uint8_t landed_state = 0;       ///< MAV_LANDED_STATE; 0 until EXTENDED_SYS_STATE arrives
  bool have_position = false;     ///< a LOCAL_POSITION_NED arrived
  fleet::Vec3 ned;                ///< m, north east down, the vehicle's local frame
  fleet::Vec3 ned_velocity;       ///< m/s, north east down
  double battery = -1.0;          ///< %, -1 unknown
  bool have_altitude = false;     ///< a GLOBAL_POSITION_INT arrived
  double amsl_m = 0.0;            ///< altitude above mean sea level
  double relative_alt_m = 0.0;    ///< altitude above home
  double heading_deg = -1.0;      ///< GLOBAL_POSITION_INT.hdg in degrees, -1 unknown

  /// On the ground: EXTENDED_SYS_STATE says so; without it, disarmed or within 0.3 m of
  /// the local origin's height.
  bool landed() const;
};

/// What a frame changed, so the adapter publishes and checks goals only when needed.
struct Changes {
  bool heartbeat = false;
  bool position = false;
  bool armed = false;
  bool landed = false;
  /// The frame was refused and changed nothing: which message and why (NaN, infinity, a
  /// value beyond any vehicle, an unknown enum value). nullptr for a frame taken.
  const char* rejected = nullptr;
};

/// Folds one telemetry frame (HEARTBEAT, LOCAL_POSITION_NED, EXTENDED_SYS_STATE,
/// SYS_STATUS, BATTERY_STATUS, GLOBAL_POSITION_INT) into `v`; other messages change nothing.
/// A frame has passed its CRC, but its values still come from outside: one with NaN, an
/// infinity, a value out of range or an unknown enum value is refused whole (Changes::rejected).
Changes apply_telemetry(VehicleState& v, const mavlink::Frame& frame);

fleet::Vec3 ned_to_mission(fleet::Vec3 ned, fleet::Vec3 home);
fleet::Vec3 mission_to_ned(fleet::Vec3 mission, fleet::Vec3 home);

}  // namespace eamos::mavlink_adapter
