#pragma once
// What differs between PX4 and ArduPilot, in one row per autopilot, so the adapter's logic
// never asks "which autopilot is this?". The row is chosen from the vehicle's first
// HEARTBEAT (its `autopilot` field).
#include <array>
#include <cstdint>
#include <string>

#include "mavlink/enums.h"

namespace eamos::mavlink_adapter {

struct Autopilot {
  const char* name;              ///< "PX4", "ArduPilot": for messages
  uint8_t mav_autopilot;         ///< HEARTBEAT.autopilot value that selects this row
  uint32_t setpoint_mode;        ///< custom_mode in which position setpoints are flown
  const char* setpoint_mode_name;  ///< "OFFBOARD" (PX4), "GUIDED" (ArduPilot)
  /// PX4 refuses OFFBOARD unless setpoints already stream (and leaves it when they stop).
  bool stream_before_switch;
  /// ArduPilot Copter takes off only in GUIDED; PX4 switches to AUTO.TAKEOFF by itself.
  bool takeoff_in_setpoint_mode;
  /// MAV_CMD_NAV_TAKEOFF param7: PX4 reads metres above mean sea level, ArduPilot metres
  /// above home.
  bool takeoff_altitude_amsl;
  /// PX4 packs custom_mode as main mode << 16 | sub mode << 24 and DO_SET_MODE takes them
  /// as param2/param3; ArduPilot's custom_mode is the mode number, DO_SET_MODE param2.
  bool main_sub_modes;
  /// PX4 flies MAV_CMD_DO_ORBIT itself, in a mode of its own (`orbit_mode`); ArduPilot Copter
  /// has no DO_ORBIT, so the adapter flies the circle with setpoints there.
  bool do_orbit;
  uint32_t orbit_mode;  ///< custom_mode while flying DO_ORBIT (unused without do_orbit)
  /// Where a cancelled DO_ORBIT goes at once: the autopilot's hold (PX4: AUTO.LOITER), so the
  /// vehicle stops circling before the setpoint stream has earned the setpoint mode.
  uint32_t hold_mode;
  /// The mode switched to before arming from a mode that cannot arm (`land_mode`,
  /// `rtl_mode`: where a landing leaves the vehicle): ArduCopter cannot arm in LAND or RTL
  /// ("Arm: LAND mode not armable"), its GUIDED can with a position; PX4's AUTO.LOITER can.
  uint32_t arm_mode;
  uint32_t land_mode;
  uint32_t rtl_mode;
  /// The command that takes one picture: ArduPilot (4.4+) MAV_CMD_IMAGE_START_CAPTURE to its
  /// AP_Camera; PX4's camera_trigger takes only MAV_CMD_DO_DIGICAM_CONTROL (param5 = 1: shoot).
  uint16_t picture_command;
};

/// False for the modes the autopilot refuses to arm in, or may refuse: PX4's OFFBOARD, where
/// it stands after a mission that ended with NAV_LAND, arms only while setpoints stream, and an
/// Arm comes before them.
bool can_arm_in(const Autopilot& a, uint32_t custom_mode);

/// The row for a HEARTBEAT.autopilot value; nullptr for autopilots we do not fly.
const Autopilot* autopilot_for(uint8_t mav_autopilot);

/// DO_SET_MODE param1…param3 that select `custom_mode`.
std::array<float, 3> set_mode_params(const Autopilot& a, uint32_t custom_mode);

/// A flight mode in words, e.g. "OFFBOARD", "AUTO.LOITER", "GUIDED", or its number.
std::string mode_name(const Autopilot& a, uint32_t custom_mode);

namespace px4 = mavlink::px4;

}  // namespace eamos::mavlink_adapter
