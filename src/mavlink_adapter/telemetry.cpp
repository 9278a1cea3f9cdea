#include "mavlink_adapter/telemetry.h"

#include <cmath>

#include "mavlink/enums.h"
#include "mavlink/payloads.h"
#include "mid/vec.h"

namespace eamos::mavlink_adapter {

namespace ml = eamos::mavlink;

bool VehicleState::landed() const {
  // Without EXTENDED_SYS_STATE: disarmed, or less than 0.3 m above the local origin.
  if (landed_state == ml::landed::UNDEFINED) return !armed || !have_position || -ned.z < 0.3;
  return landed_state == ml::landed::ON_GROUND;
}

double VehicleState::track_span_s() const {
  if (track.size() < 2 || track.back().first - track.front().first < kTrackMinSpanMs) return 0.0;
  return (track.back().first - track.front().first) / 1000.0;
}

double VehicleState::settling_speed() const {
  const double span_s = track_span_s();
  if (span_s <= 0.0) return norm(ned_velocity);
  return norm(track.back().second - track.front().second) / span_s;
}

namespace {

// Bounds beyond any vehicle the adapter flies: a value past them is a corrupt or hostile frame.
constexpr double kMaxLocalPositionM = 1e6;   // 1,000 km from the local origin
constexpr double kMaxVelocityMps = 1000;
constexpr int32_t kMaxAltitudeMm = 100'000'000;  // 100 km

bool within(float v, double bound) { return std::isfinite(v) && std::fabs(v) <= bound; }

bool on_earth(int32_t lat_e7, int32_t lon_e7) {
  return lat_e7 >= -900'000'000 && lat_e7 <= 900'000'000 && lon_e7 >= -1'800'000'000 && lon_e7 <= 1'800'000'000;
}

const char* refusal(const ml::Message& m) {
  if (auto p = ml::unpack_local_position_ned(m)) {
    bool ok = within(p->x, kMaxLocalPositionM) && within(p->y, kMaxLocalPositionM) &&
              within(p->z, kMaxLocalPositionM) && within(p->vx, kMaxVelocityMps) &&
              within(p->vy, kMaxVelocityMps) && within(p->vz, kMaxVelocityMps);
    return ok ? nullptr : "LOCAL_POSITION_NED with NaN, an infinity or a value out of range";
  }
  if (auto e = ml::unpack_extended_sys_state(m))
    return e->landed_state <= ml::landed::LANDING ? nullptr : "EXTENDED_SYS_STATE with an unknown landed state";
  if (auto s = ml::unpack_sys_status(m))
    return s->battery_remaining >= -1 && s->battery_remaining <= 100 ? nullptr
                                                                      : "SYS_STATUS with a battery beyond 0 to 100 %";
  if (auto b = ml::unpack_battery_status(m))
    return b->battery_remaining >= -1 && b->battery_remaining <= 100
               ? nullptr
               : "BATTERY_STATUS with a battery beyond 0 to 100 %";
  if (auto g = ml::unpack_global_position_int(m)) {
    bool ok = g->alt >= -kMaxAltitudeMm && g->alt <= kMaxAltitudeMm && g->relative_alt >= -kMaxAltitudeMm &&
              g->relative_alt <= kMaxAltitudeMm;
    if (!ok) return "GLOBAL_POSITION_INT with an altitude beyond 100 km";
    return on_earth(g->lat, g->lon) ? nullptr : "GLOBAL_POSITION_INT with a latitude or longitude off the earth";
  }
  if (auto o = ml::unpack_orbit_execution_status(m)) {
    bool ok = within(o->radius, kMaxLocalPositionM) && (!ml::is_global_frame(o->frame) || on_earth(o->x, o->y));
    return ok ? nullptr : "ORBIT_EXECUTION_STATUS with NaN, a radius out of range or a centre off the earth";
  }
  return nullptr;
}

}  // namespace

Changes apply_telemetry(VehicleState& v, const ml::Frame& frame) {
  Changes c;
  const ml::Message& m = frame.message;
  if ((c.rejected = refusal(m))) return c;
  bool was_landed = v.landed();
  if (auto hb = ml::unpack_heartbeat(m)) {
    c.heartbeat = true;
    v.heard = true;
    v.autopilot = hb->autopilot;
    v.custom_mode = hb->custom_mode;
    bool armed = (hb->base_mode & ml::mode_flag::SAFETY_ARMED) != 0;
    if (v.armed_by_ack) {
      c.armed_unconfirmed = armed != *v.armed_by_ack;
      if (c.armed_unconfirmed) armed = *v.armed_by_ack;
      v.armed_by_ack.reset();
    }
    c.armed = armed != v.armed;
    v.armed = armed;
  } else if (auto p = ml::unpack_local_position_ned(m)) {
    c.position = true;
    v.have_position = true;
    v.ned = {p->x, p->y, p->z};
    v.ned_velocity = {p->vx, p->vy, p->vz};
    // A time going back is a reboot of the autopilot (or a report out of order): start anew.
    if (!v.track.empty() && p->time_boot_ms < v.track.back().first) v.track.clear();
    v.track.emplace_back(p->time_boot_ms, v.ned);
    while (p->time_boot_ms - v.track.front().first > kTrackWindowMs) v.track.pop_front();
  } else if (auto e = ml::unpack_extended_sys_state(m)) {
    v.landed_state = e->landed_state;
  } else if (auto s = ml::unpack_sys_status(m)) {
    if (s->battery_remaining >= 0) v.battery = s->battery_remaining;
  } else if (auto b = ml::unpack_battery_status(m)) {
    if (b->battery_remaining >= 0) v.battery = b->battery_remaining;
  } else if (auto g = ml::unpack_global_position_int(m)) {
    v.have_altitude = true;
    v.amsl_m = g->alt / 1000.0;
    v.relative_alt_m = g->relative_alt / 1000.0;
    // UINT16_MAX: the vehicle does not know; anything else beyond 359.99° is not a heading.
    v.heading_deg = g->hdg < 36000 ? g->hdg / 100.0 : -1.0;
    v.lat_e7 = g->lat, v.lon_e7 = g->lon;
    v.global_time_boot_ms = g->time_boot_ms;
    v.global_velocity = {g->vx / 100.0, g->vy / 100.0, g->vz / 100.0};
    c.global_position = true;
  } else if (auto o = ml::unpack_orbit_execution_status(m)) {
    // A centre in a local frame would need the autopilot's local origin: not used.
    if (ml::is_global_frame(o->frame)) {
      v.have_orbit_centre = true;
      v.orbit_centre_lat_e7 = o->x, v.orbit_centre_lon_e7 = o->y;
    }
  }
  c.landed = v.landed() != was_landed;
  return c;
}

namespace {
constexpr double kEarthRadiusM = 6'371'000.0;  // PX4's and ArduPilot's mean radius
constexpr double kRadPerE7 = M_PI / 180.0 * 1e-7;
}  // namespace

std::pair<int32_t, int32_t> offset_lat_lon(int32_t lat, int32_t lon, double north_m, double east_m) {
  const double dlat = north_m / kEarthRadiusM / kRadPerE7;
  const double mid_lat = (lat + dlat / 2.0) * kRadPerE7;
  const double dlon = east_m / (kEarthRadiusM * std::cos(mid_lat)) / kRadPerE7;
  return {static_cast<int32_t>(std::lround(lat + dlat)), static_cast<int32_t>(std::lround(lon + dlon))};
}

fleet::Vec3 north_east_between(int32_t from_lat, int32_t from_lon, int32_t to_lat, int32_t to_lon) {
  const double mid_lat = (static_cast<double>(from_lat) + to_lat) / 2.0 * kRadPerE7;
  const double north = (static_cast<double>(to_lat) - from_lat) * kRadPerE7 * kEarthRadiusM;
  const double east = (static_cast<double>(to_lon) - from_lon) * kRadPerE7 * kEarthRadiusM * std::cos(mid_lat);
  return {north, east, 0.0};
}

fleet::Vec3 ned_to_mission(fleet::Vec3 ned, fleet::Vec3 home) {
  return {home.x + ned.y, home.y + ned.x, home.z - ned.z};
}

fleet::Vec3 mission_to_ned(fleet::Vec3 p, fleet::Vec3 home) {
  return {p.y - home.y, p.x - home.x, home.z - p.z};
}

fleet::Vec3 mission_position(const VehicleState& v, fleet::Vec3 home) {
  return v.have_position ? ned_to_mission(v.ned, home) : home;
}

}  // namespace eamos::mavlink_adapter
