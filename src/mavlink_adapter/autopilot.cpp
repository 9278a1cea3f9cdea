#include "mavlink_adapter/autopilot.h"

#include "mavlink/enums.h"

namespace eamos::mavlink_adapter {

namespace {

// ArduCopter mode numbers (ArduPilot's Copter/mode.h).
constexpr uint32_t kCopterGuided = 4;
constexpr uint32_t kCopterLoiter = 5;
constexpr uint32_t kCopterRtl = 6;
constexpr uint32_t kCopterLand = 9;

const Autopilot kPx4{"PX4", mavlink::autopilot::PX4, px4::OFFBOARD, "OFFBOARD",
                     /*stream_before_switch=*/true, /*takeoff_in_setpoint_mode=*/false,
                     /*takeoff_altitude_amsl=*/true, /*main_sub_modes=*/true,
                     /*do_orbit=*/true, px4::ORBIT, px4::LOITER,
                     /*arm_mode=*/px4::LOITER, px4::LAND, px4::RTL, mavlink::cmd::DO_DIGICAM_CONTROL};
const Autopilot kArduPilot{"ArduPilot", mavlink::autopilot::ARDUPILOTMEGA, kCopterGuided, "GUIDED",
                           /*stream_before_switch=*/false, /*takeoff_in_setpoint_mode=*/true,
                           /*takeoff_altitude_amsl=*/false, /*main_sub_modes=*/false,
                           /*do_orbit=*/false, 0, kCopterLoiter,
                           /*arm_mode=*/kCopterGuided, kCopterLand, kCopterRtl,
                           mavlink::cmd::IMAGE_START_CAPTURE};

}  // namespace

const Autopilot* autopilot_for(uint8_t mav_autopilot) {
  for (const Autopilot* a : {&kPx4, &kArduPilot})
    if (a->mav_autopilot == mav_autopilot) return a;
  return nullptr;
}

bool can_arm_in(const Autopilot& a, uint32_t custom_mode) {
  if (a.stream_before_switch && custom_mode == a.setpoint_mode) return false;
  return custom_mode != a.land_mode && custom_mode != a.rtl_mode;
}

std::array<float, 3> set_mode_params(const Autopilot& a, uint32_t custom_mode) {
  const float custom = mavlink::mode_flag::CUSTOM_MODE_ENABLED;
  if (!a.main_sub_modes) return {custom, static_cast<float>(custom_mode), 0.0f};
  return {custom, static_cast<float>((custom_mode >> 16) & 0xFF),
          static_cast<float>((custom_mode >> 24) & 0xFF)};
}

std::string mode_name(const Autopilot& a, uint32_t m) {
  if (a.main_sub_modes) {
    switch (m) {
      case px4::OFFBOARD: return "OFFBOARD";
      case px4::LOITER: return "AUTO.LOITER";
      case px4::TAKEOFF: return "AUTO.TAKEOFF";
      case px4::LAND: return "AUTO.LAND";
      case px4::RTL: return "AUTO.RTL";
      case px4::mode(px4::MAIN_POSCTL): return "POSCTL";
      case px4::ORBIT: return "ORBIT";
    }
  } else {
    switch (m) {
      case 0: return "STABILIZE";
      case kCopterGuided: return "GUIDED";
      case kCopterLoiter: return "LOITER";
      case 6: return "RTL";
      case 9: return "LAND";
    }
  }
  return "mode " + std::to_string(m);
}

}  // namespace eamos::mavlink_adapter
