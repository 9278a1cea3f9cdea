#include "mavlink_adapter/autopilot_params.h"

#include <cmath>
#include <algorithm>
#include <optional>

#include "diag/number.h"

namespace eamos::mavlink_adapter {

using diag::number_text;

namespace {

// ArduCopter (its parameter docs): waypoint speeds in cm/s; LAND_SPEED is the last 10 m
// (LAND_ALT_LOW) of a landing, LAND_SPEED_HIGH above it (0: WPNAV_SPEED_DN). The whole
// descent is counted at the slower one: a deadline must not be too short.
const std::vector<LimitParam> kArduPilotLimits = {
    {"WPNAV_SPEED", LimitKind::speed, 0.01},     {"WPNAV_SPEED_UP", LimitKind::climb, 0.01},
    {"WPNAV_SPEED_DN", LimitKind::descent, 0.01}, {"LAND_SPEED", LimitKind::land, 0.01},
    {"LAND_SPEED_HIGH", LimitKind::land, 0.01},
    {"MOT_SPOOL_TIME", LimitKind::takeoff_delay, 1.0}, {"TKOFF_SLEW_TIME", LimitKind::takeoff_delay, 1.0},
    {"WPNAV_ACCEL", LimitKind::accel, 0.01},  // GUIDED's position controller limit (cm/s²)
    // RTL (mode_rtl): climb to RTL_ALT (cm), at least RTL_CLIMB_MIN more; home at RTL_SPEED
    // (cm/s, 0: WPNAV_SPEED); loiter RTL_LOIT_TIME (ms); land, or stop at RTL_ALT_FINAL (cm).
    {"RTL_ALT", LimitKind::return_home, 0.01},       {"RTL_CLIMB_MIN", LimitKind::return_home, 0.01},
    {"RTL_SPEED", LimitKind::return_home, 0.01},     {"RTL_LOIT_TIME", LimitKind::return_home, 0.001},
    {"RTL_ALT_FINAL", LimitKind::return_home, 0.01},
};
// PX4 (multicopter position control): m/s. A takeoff climbs at MPC_TKO_SPEED, a landing
// ends at MPC_LAND_SPEED.
const std::vector<LimitParam> kPx4Limits = {
    {"MPC_XY_CRUISE", LimitKind::speed, 1.0},    {"MPC_Z_VEL_MAX_UP", LimitKind::climb, 1.0},
    {"MPC_TKO_SPEED", LimitKind::climb, 1.0},    {"MPC_Z_VEL_MAX_DN", LimitKind::descent, 1.0},
    {"MPC_LAND_SPEED", LimitKind::land, 1.0},
    {"COM_SPOOLUP_TIME", LimitKind::takeoff_delay, 1.0}, {"MPC_TKO_RAMP_T", LimitKind::takeoff_delay, 1.0},
    {"MPC_ACC_HOR", LimitKind::accel, 1.0},
    // Return mode: climb to RTL_RETURN_ALT (m) above home, fly home, descend, wait
    // RTL_LAND_DELAY (s; negative: hover there for good), land.
    {"RTL_RETURN_ALT", LimitKind::return_home, 1.0}, {"RTL_LAND_DELAY", LimitKind::return_home, 1.0},
    {"MC_ORBIT_RAD_MAX", LimitKind::orbit_radius, 1.0},
};

const char* fleet_key(LimitKind k) {
  switch (k) {
    case LimitKind::speed: return "max_speed";
    case LimitKind::climb: return "max_climb";
    case LimitKind::descent:
    case LimitKind::land: return "max_descent";
    case LimitKind::takeoff_delay:
    case LimitKind::accel: return "";
    case LimitKind::return_home:
    case LimitKind::orbit_radius: return "";
  }
  return "";
}

// The slowest value the autopilot gave for `kind`, and which parameter said it.
struct Slowest {
  std::optional<double> mps;
  std::string param;
};

Slowest slowest(const std::vector<LimitParam>& params, LimitKind kind,
                const std::map<std::string, float>& values) {
  Slowest s;
  for (const LimitParam& p : params) {
    if (p.kind != kind) continue;
    auto it = values.find(p.name);
    // 0 means "use another parameter" (LAND_SPEED_HIGH); NaN or a negative value is no limit
    // an autopilot flies by: the fleet's limit stands.
    if (it == values.end() || !std::isfinite(it->second) || it->second <= 0) continue;
    double mps = it->second * p.to_mps;
    if (!s.mps || mps < *s.mps) s = {mps, p.name};
  }
  return s;
}

// The return-to-launch parameters the autopilot told, in metres, m/s and seconds; 0 is a
// value here (RTL_ALT 0: return at the current altitude). One it did not tell leaves the
// straight way home, with a warning.
void read_return_profile(const Autopilot& a, const std::vector<LimitParam>& params,
                         const std::map<std::string, float>& values, FlightLimits& out) {
  std::map<std::string, double> rtl;
  for (const LimitParam& p : params) {
    if (p.kind != LimitKind::return_home) continue;
    auto it = values.find(p.name);
    if (it == values.end() || !std::isfinite(it->second)) {
      out.warnings.push_back(std::string(a.name) + " did not tell " + p.name +
                             "; ReturnHome's deadline assumes its return flies straight home and down");
      continue;
    }
    rtl[p.name] = it->second * p.to_mps;
    out.summary += std::string(out.summary.empty() ? "" : ", ") + p.name + " " + number_text(rtl[p.name]);
  }
  auto value = [&rtl](const char* name) { return rtl.contains(name) ? rtl[name] : 0.0; };
  ReturnProfile& r = out.rtl;
  r.altitude_m = std::max({0.0, value("RTL_ALT"), value("RTL_RETURN_ALT")});
  r.min_climb_m = std::max(0.0, value("RTL_CLIMB_MIN"));
  r.speed_mps = std::max(0.0, value("RTL_SPEED"));
  r.wait_s = std::max({0.0, value("RTL_LOIT_TIME"), value("RTL_LAND_DELAY")});
  r.lands = value("RTL_ALT_FINAL") <= 0 && value("RTL_LAND_DELAY") >= 0;
  if (!r.lands)
    out.warnings.push_back(std::string(a.name) + "'s return does not land (" +
                           (value("RTL_ALT_FINAL") > 0 ? "RTL_ALT_FINAL > 0" : "RTL_LAND_DELAY < 0") +
                           "): a ReturnHome will time out hovering over home");
}

}  // namespace

std::vector<LimitParam> limit_params(const Autopilot& a) {
  return a.mav_autopilot == mavlink::autopilot::PX4 ? kPx4Limits : kArduPilotLimits;
}

FlightLimits combine_limits(const Autopilot& a, const fleet::Limits& fleet,
                            const std::map<std::string, float>& values) {
  const std::vector<LimitParam> params = limit_params(a);
  FlightLimits out;
  out.motion = fleet;
  out.land_mps = fleet.max_descent_mps;
  struct Slot { LimitKind kind; double& value; };
  for (Slot slot : {Slot{LimitKind::speed, out.motion.max_speed_mps}, Slot{LimitKind::climb, out.motion.max_climb_mps},
                    Slot{LimitKind::descent, out.motion.max_descent_mps}, Slot{LimitKind::land, out.land_mps}}) {
    Slowest s = slowest(params, slot.kind, values);
    if (!s.mps) {
      std::string names;
      for (const LimitParam& p : params)
        if (p.kind == slot.kind) names += std::string(names.empty() ? "" : " or ") + p.name;
      out.warnings.push_back(std::string(a.name) + " did not tell " + names + "; deadlines use the fleet's " +
                             fleet_key(slot.kind) + " " + number_text(slot.value) + " m/s");
      continue;
    }
    out.summary += std::string(out.summary.empty() ? "" : ", ") + s.param + " " + number_text(*s.mps) + " m/s";
    // Landing is always slower than a fleet's descent on some autopilot: not worth a warning.
    if (slot.value > *s.mps && slot.kind != LimitKind::land)
      out.warnings.push_back("the fleet's " + std::string(fleet_key(slot.kind)) + " " + number_text(slot.value) +
                             " m/s is above " + a.name + "'s " + s.param + " " + number_text(*s.mps) +
                             " m/s: the vehicle flies at most " + number_text(*s.mps) + " m/s, deadlines use it");
    slot.value = std::min(slot.value, *s.mps);
  }
  out.land_mps = std::min(out.land_mps, out.motion.max_descent_mps);
  // No warning either way: only the orbit's speed depends on it, and it flies slower.
  if (Slowest a = slowest(params, LimitKind::accel, values); a.mps) {
    out.motion.max_accel_mps2 = std::min(out.motion.max_accel_mps2, *a.mps);
    out.summary += std::string(out.summary.empty() ? "" : ", ") + a.param + " " + number_text(*a.mps) + " m/s²";
  }
  // Delays add up; one the autopilot does not have (an older version) is no delay.
  for (const LimitParam& p : params) {
    auto it = values.find(p.name);
    if (p.kind != LimitKind::takeoff_delay || it == values.end() || !std::isfinite(it->second) || it->second <= 0)
      continue;
    out.takeoff_delay_s += it->second * p.to_mps;
    out.summary +=
        std::string(out.summary.empty() ? "" : ", ") + p.name + " " + number_text(it->second * p.to_mps) + " s";
  }
  read_return_profile(a, params, values, out);
  // Unknown (ArduPilot, an older PX4): the autopilot judges the radius when DO_ORBIT comes.
  if (Slowest r = slowest(params, LimitKind::orbit_radius, values); r.mps) out.orbit_radius_max_m = *r.mps;
  return out;
}

double return_home_duration_s(const FlightLimits& l, double height_m, double distance_m) {
  const ReturnProfile& r = l.rtl;
  double top = std::max({height_m, r.altitude_m, height_m + r.min_climb_m});
  double speed = r.speed_mps > 0 ? std::min(r.speed_mps, l.motion.max_speed_mps) : l.motion.max_speed_mps;
  return (top - height_m) / l.motion.max_climb_mps + distance_m / speed + r.wait_s +
         std::max(0.0, top) / l.land_mps;
}

}  // namespace eamos::mavlink_adapter
