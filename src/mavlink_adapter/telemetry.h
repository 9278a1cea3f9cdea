#pragma once
// What the adapter knows about its vehicle, from the telemetry it streams, and the mapping
// between the autopilot's local NED frame and the mission frame. The vehicle's local origin
// is where its estimator started (for a vehicle that boots where it takes off: its home), so
//   mission = home + (NED east, NED north, -NED down),
// with `home` the drone's home from the fleet file.
#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <utility>

#include "fleet/fleet.h"
#include "mavlink/frame.h"

namespace eamos::mavlink_adapter {

struct VehicleState {
  bool heard = false;             ///< a HEARTBEAT arrived
  uint8_t autopilot = 0;          ///< MAV_AUTOPILOT of the HEARTBEAT
  uint32_t custom_mode = 0;       ///< the autopilot's flight mode
  bool armed = false;
  /// The armed state an accepted ARM or DISARM's COMMAND_ACK gave, until the next HEARTBEAT.
  /// Nothing in MAVLink orders a HEARTBEAT made before the command took effect ahead of its
  /// ACK (the autopilot answers from its command handler and reports its state from
  /// another task; a link may reorder), so the first HEARTBEAT after the ACK that says
  /// otherwise is not believed; the next one is.
  std::optional<bool> armed_by_ack;
  /// An accepted ARM (true) or DISARM (false): armed as its ACK says until a HEARTBEAT
  /// confirms it, and the first one that does not is not believed.
  void armed_by_command(bool now_armed) {
    armed = now_armed;
    armed_by_ack = now_armed;
  }
  uint8_t landed_state = 0;       ///< MAV_LANDED_STATE; 0 until EXTENDED_SYS_STATE arrives
  bool have_position = false;     ///< a LOCAL_POSITION_NED arrived
  fleet::Vec3 ned;                ///< m, north east down, the vehicle's local frame
  fleet::Vec3 ned_velocity;       ///< m/s, north east down
  /// The last LOCAL_POSITION_NEDs within kTrackWindowMs of the newest, by the vehicle's
  /// time_boot_ms: how far the position itself moved, beside the velocity the estimator says.
  std::deque<std::pair<uint32_t, fleet::Vec3>> track;
  double battery = -1.0;          ///< %, -1 unknown
  bool have_altitude = false;     ///< a GLOBAL_POSITION_INT arrived
  double amsl_m = 0.0;            ///< altitude above mean sea level
  double relative_alt_m = 0.0;    ///< altitude above home
  double heading_deg = -1.0;      ///< GLOBAL_POSITION_INT.hdg in degrees, -1 unknown
  int32_t lat_e7 = 0, lon_e7 = 0; ///< GLOBAL_POSITION_INT's, degE7
  uint32_t global_time_boot_ms = 0;
  fleet::Vec3 global_velocity;    ///< m/s, north east down, GLOBAL_POSITION_INT's
  /// The centre of the orbit the autopilot flies (ORBIT_EXECUTION_STATUS in a global frame),
  /// degE7; have_orbit_centre only while the newest such report is of the current orbit.
  bool have_orbit_centre = false;
  int32_t orbit_centre_lat_e7 = 0, orbit_centre_lon_e7 = 0;

  /// On the ground: EXTENDED_SYS_STATE says so; without it, disarmed or within 0.3 m of
  /// the local origin's height.
  bool landed() const;
  /// m/s over the track (its oldest to its newest position, in the vehicle's time); the
  /// estimator's ned_velocity while the track spans less than kTrackMinSpanMs.
  double settling_speed() const;
  /// Vehicle seconds from the track's oldest to its newest position; 0 while it spans less
  /// than kTrackMinSpanMs (too short to judge a motion by).
  double track_span_s() const;
};

/// PX4 SIH on a loaded machine was seen holding 0.3-0.6 m short of a setpoint for seconds
/// while its estimator reported 0.4-0.6 m/s towards it, about its position gain times the
/// error: a velocity estimate off by that much, which the position did not follow. A goal is
/// judged on the position, so is its standstill.
inline constexpr uint32_t kTrackWindowMs = 500;
inline constexpr uint32_t kTrackMinSpanMs = 300;

/// What a frame changed, so the adapter publishes and checks goals only when needed.
struct Changes {
  bool heartbeat = false;
  bool position = false;
  bool armed = false;
  /// A HEARTBEAT contradicted armed_by_ack and was not believed (VehicleState::armed_by_ack).
  bool armed_unconfirmed = false;
  bool landed = false;
  bool global_position = false;  ///< a GLOBAL_POSITION_INT was taken
  /// The frame was refused and changed nothing: which message and why (NaN, infinity, a
  /// value beyond any vehicle, an unknown enum value). nullptr for a frame taken.
  const char* rejected = nullptr;
};

/// Folds one telemetry frame (HEARTBEAT, LOCAL_POSITION_NED, EXTENDED_SYS_STATE,
/// SYS_STATUS, BATTERY_STATUS, GLOBAL_POSITION_INT, ORBIT_EXECUTION_STATUS) into `v`; other messages change nothing.
/// A frame has passed its CRC, but its values still come from outside: one with NaN, an
/// infinity, a value out of range or an unknown enum value is refused whole (Changes::rejected).
Changes apply_telemetry(VehicleState& v, const mavlink::Frame& frame);

/// Horizontal metres (north, east) from `from` to `to`, both degE7: flat earth, which over the
/// tens of metres of an orbit errs by far less than the position estimate.
fleet::Vec3 north_east_between(int32_t from_lat, int32_t from_lon, int32_t to_lat, int32_t to_lon);
/// The point `north_m`, `east_m` from (lat, lon), in degE7: north_east_between's inverse.
std::pair<int32_t, int32_t> offset_lat_lon(int32_t lat, int32_t lon, double north_m, double east_m);

fleet::Vec3 ned_to_mission(fleet::Vec3 ned, fleet::Vec3 home);
fleet::Vec3 mission_to_ned(fleet::Vec3 mission, fleet::Vec3 home);
/// Where the vehicle is in the mission frame; `home` until its first position report.
fleet::Vec3 mission_position(const VehicleState& v, fleet::Vec3 home);

}  // namespace eamos::mavlink_adapter
