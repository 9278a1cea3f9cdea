// MAV_CMD_DO_ORBIT as PX4 flies it, simplified: the vehicle enters its Orbit mode and circles
// the centre (only "where it is now" is supported) until another mode takes over. Like PX4's
// orbit flight task, a point moves around the circle at the commanded speed and the vehicle
// follows it. As in PX4 (FlightModeManager keeps a running task; FlightTaskOrbit sets its
// centre only when it starts), DO_ORBIT sent again in the Orbit mode keeps the centre and
// changes radius, speed and direction, approaching the new circle again only when the vehicle
// is further than PX4's acceptance radius from it.
#include <algorithm>
#include <cmath>

#include "mavlink/enums.h"
#include "mid/vec.h"
#include "sim/motion.h"
#include "sim_vehicle/sim_vehicle.h"

namespace eamos::sim_vehicle {

namespace ml = eamos::mavlink;
using fleet::Vec3;

namespace {
constexpr double kTickS = 0.1;
// PX4's bounds: radius from 1 m to MC_ORBIT_RAD_MAX (1000 m); 1 m/s when no speed is given.
constexpr double kMinRadius = 1.0, kMaxRadius = 1000.0, kDefaultSpeed = 1.0;
constexpr double kOnCircleM = 0.5;
constexpr double kAcceptanceM = 1.0;  ///< PX4 FlightTaskOrbit's _horizontal_acceptance_radius
}  // namespace

uint8_t SimVehicle::start_orbit(const ml::CommandLong& c, std::optional<Vec3> centre) {
  if (!dialect_.do_orbit) return ml::result::UNSUPPORTED;
  if (options_.refuse_orbit) return ml::result::DENIED;
  mid::DroneState s = drone_.state();
  if (!s.armed || s.landed) return ml::result::DENIED;  // PX4: Orbit only in the air
  const auto& p = c.param;
  double radius = std::isnan(p[0]) ? 5.0 : std::fabs(p[0]);
  if (radius < kMinRadius || radius > kMaxRadius) return ml::result::DENIED;
  // A centre as COMMAND_LONG floats would be off by metres: PX4 takes it, this vehicle does not.
  if (!std::isnan(p[4]) || !std::isnan(p[5])) return ml::result::DENIED;
  // As fast as asked, but no faster than the vehicle can turn on this circle (PX4 caps the
  // centripetal acceleration too). The vehicle's limits are the defaults vehicle_settings gives.
  double asked = std::isnan(p[1]) ? kDefaultSpeed : std::fabs(p[1]);
  double speed = std::min(asked, sim::orbit_speed(radius, fleet::Limits{}));
  double z = std::isnan(p[6]) ? s.z : p[6] - options_.home_amsl_m;
  // PX4: positive radius (or NaN, its default) = clockwise.
  double direction = !std::isnan(p[0]) && p[0] < 0 ? 1.0 : -1.0;
  orbit_commands_.push_back(c);
  if (orbit_commands_.size() > 1000) orbit_commands_.erase(orbit_commands_.begin());  // a long run
  if (mode_ == Mode::orbit) {
    // Already orbiting: the same centre, angle and altitude, the new radius and speed.
    Orbit& o = orbit_;
    o.radius = radius;
    o.speed = speed;
    o.direction = direction;
    if (centre) o.centre.x = centre->x, o.centre.y = centre->y;  // PX4 takes a centre named again
    double off = std::fabs(std::hypot(s.x - o.centre.x, s.y - o.centre.y) - flown_radius());
    if (o.on_circle && off > kAcceptanceM) o.on_circle = false;
    return ml::result::ACCEPTED;
  }
  Vec3 at = centre ? Vec3{centre->x, centre->y, z} : Vec3{s.x, s.y, z};
  // From where the vehicle is on (or off) the circle, not from its east point.
  double angle = std::atan2(s.y - at.y, s.x - at.x);
  orbit_ = {at, radius, speed, direction, centre ? angle : 0.0, false};
  orbit_start_ = {at, {s.x, s.y, s.z}};
  mode_ = Mode::orbit;
  flying_ = false;
  loop_.cancel(orbit_timer_);
  orbit_tick();
  return ml::result::ACCEPTED;
}

double SimVehicle::flown_radius() const { return orbit_.radius * (1.0 - options_.orbit_shortfall); }

void SimVehicle::orbit_tick() {
  orbit_timer_ = mid::kNoTimer;
  if (mode_ != Mode::orbit) return;  // another mode took over: the orbit ends with it
  mid::DroneState s = drone_.state();
  Orbit& o = orbit_;
  const double r = flown_radius();
  if (!o.on_circle) {
    // Out to the circle's point at the orbit's angle (at the start: its east point), then around.
    Vec3 entry{o.centre.x + r * std::cos(o.angle), o.centre.y + r * std::sin(o.angle), o.centre.z};
    o.on_circle = horizontal_norm(Vec3{s.x, s.y, s.z} - entry) <= kOnCircleM;
  } else {
    o.angle = std::fmod(o.angle + o.direction * o.speed * kTickS / r, 2.0 * M_PI);
  }
  Vec3 target{o.centre.x + r * std::cos(o.angle), o.centre.y + r * std::sin(o.angle), o.centre.z};
  start("FlyTo", {target.x, target.y, target.z});
  orbit_timer_ = loop_.after(kTickS, [this] { orbit_tick(); });
}

}  // namespace eamos::sim_vehicle
