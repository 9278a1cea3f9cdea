// Giving way to another drone (dex/separation.h) on a MAVLink vehicle: the goal-directed
// motions the adapter flies with position setpoints are held by moving the setpoint to
// where the vehicle is (raised or lowered as asked) and resumed by sending the goal again.
// A motion the autopilot flies in a mode of its own (NAV_TAKEOFF, NAV_LAND, RTL) is not
// held: switching modes under it would fight the autopilot; the other drone gives way.
#include "mavlink_adapter/mavlink_drone.h"

namespace eamos::mavlink_adapter {

bool MavlinkDrone::hold_vehicle(mid::ActionId id, double climb_m) {
  if (id != motion_owner_ || until_ != Until::reached || !goal_ || !streaming_ || orbit_.active ||
      !vehicle_.have_position)
    return false;
  fleet::Vec3 here = position();
  here.z += climb_m;
  setpoint_ = here;
  stream_setpoints();
  return true;
}

void MavlinkDrone::resume_vehicle(mid::ActionId id) {
  if (id != motion_owner_ || !goal_) return;
  setpoint_ = goal_->target();
  stream_setpoints();
}

}  // namespace eamos::mavlink_adapter
