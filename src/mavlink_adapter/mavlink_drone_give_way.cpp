// Giving way to another drone (dex/separation.h) on a MAVLink vehicle: the goal-directed
// motions the adapter flies with position setpoints are held by moving the setpoint to
// where the vehicle is (raised or lowered as asked) and resumed by sending the goal again.
// A motion the autopilot flies in a mode of its own (NAV_TAKEOFF, NAV_LAND, RTL) is not
// held: switching modes under it would fight the autopilot; the other drone gives way.
#include "mavlink_adapter/mavlink_drone.h"

namespace eamos::mavlink_adapter {

bool MavlinkDrone::hold_vehicle(mid::ActionId id, double climb_m) {
  // A goal the setpoints fly to (never an orbit, which has none).
  if (id != motion_owner_ || until_ != Until::reached || !goal_ || !stream_.streaming() || !vehicle_.have_position)
    return false;
  fleet::Vec3 here = position();
  here.z += climb_m;
  stream_.hold(here);
  return true;
}

void MavlinkDrone::resume_vehicle(mid::ActionId id) {
  if (id != motion_owner_ || !goal_) return;
  stream_.hold(goal_->target());
}

}  // namespace eamos::mavlink_adapter
