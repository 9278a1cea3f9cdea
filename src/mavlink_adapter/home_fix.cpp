// Where the vehicle stands on the Earth, for the homes check before arming (mid/home_check.h).
#include "mavlink_adapter/mavlink_drone.h"

namespace eamos::mavlink_adapter {

std::optional<mid::GlobalFix> MavlinkDrone::global_fix() const {
  // GLOBAL_POSITION_INT is the autopilot's fused estimate; without GPS it sends none.
  if (!vehicle_.have_altitude) return std::nullopt;
  return mid::GlobalFix{vehicle_.lat_e7 * 1e-7, vehicle_.lon_e7 * 1e-7};
}

}  // namespace eamos::mavlink_adapter
