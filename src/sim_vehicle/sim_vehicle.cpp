#include "sim_vehicle/sim_vehicle.h"

#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

#include "mavlink/enums.h"
#include "mid/vec.h"

namespace eamos::sim_vehicle {

namespace ml = eamos::mavlink;
namespace px4 = eamos::mavlink::px4;
using fleet::Vec3;

namespace {

fleet::DroneSettings vehicle_settings(uint8_t sysid, double battery) {
  fleet::DroneSettings s;
  s.name = "sim-vehicle-" + std::to_string(sysid);
  s.type = "Quad";
  s.battery_percent = battery;
  return s;  // home at the origin: the local NED origin is home, as on a real vehicle
}

// PX4 SITL's default home, so GLOBAL_POSITION_INT looks like a real one.
constexpr double kHomeLat = 47.397742, kHomeLon = 8.545594;
constexpr double kMetresPerDegree = 111'111.0;

/// degE7 (lat, lon) of a point of the vehicle's frame (x east, y north of home), its home
/// standing `east` and `north` metres from PX4's.
std::pair<int32_t, int32_t> lat_lon_e7(double x, double y, double east, double north) {
  double lat = kHomeLat + (y + north) / kMetresPerDegree;
  double lon = kHomeLon + (x + east) / (kMetresPerDegree * std::cos(kHomeLat * M_PI / 180.0));
  return {static_cast<int32_t>(std::lround(lat * 1e7)), static_cast<int32_t>(std::lround(lon * 1e7))};
}

/// lat_lon_e7's inverse.
std::pair<double, double> local_xy(int32_t lat_e7, int32_t lon_e7) {
  double y = (lat_e7 / 1e7 - kHomeLat) * kMetresPerDegree;
  double x = (lon_e7 / 1e7 - kHomeLon) * kMetresPerDegree * std::cos(kHomeLat * M_PI / 180.0);
  return {x, y};
}

const uint32_t kStreamed[] = {ml::msg::LOCAL_POSITION_NED, ml::msg::EXTENDED_SYS_STATE,
                              ml::msg::SYS_STATUS, ml::msg::BATTERY_STATUS,
                              ml::msg::GLOBAL_POSITION_INT};

/// HEARTBEAT or one of kStreamed: what SET_MESSAGE_INTERVAL and REQUEST_MESSAGE may ask for.
bool streamed(uint32_t id) {
  bool known = id == ml::msg::HEARTBEAT;
  for (uint32_t m : kStreamed) known = known || m == id;
  return known;
}

/// execute()'s answer for a command acknowledged when its action ends.
constexpr uint8_t kAckLater = 255;

}  // namespace

const Dialect& px4_dialect() {
  static const Dialect d{"PX4", ml::autopilot::PX4,
                         {px4::mode(px4::MAIN_POSCTL), px4::LOITER, px4::OFFBOARD, px4::TAKEOFF,
                          px4::LAND, px4::RTL, px4::ORBIT},
                         Mode::hold, true, true, false, true, true, Mode::hold, true,
                         ml::cmd::DO_DIGICAM_CONTROL, ml::msg::CAMERA_TRIGGER, true};
  return d;
}

const Dialect& ardupilot_dialect() {
  // ArduCopter: STABILIZE 0, GUIDED 4, LOITER 5, RTL 6, CIRCLE 7, LAND 9; a GUIDED takeoff
  // stays GUIDED. CIRCLE is never entered here: no DO_ORBIT, and DO_SET_MODE cannot ask for it.
  static const Dialect d{"ArduPilot", ml::autopilot::ARDUPILOTMEGA, {0, 5, 4, 4, 9, 6, 7},
                         Mode::manual, false, false, true, false, false, Mode::setpoint, false,
                         ml::cmd::IMAGE_START_CAPTURE, ml::msg::CAMERA_FEEDBACK, false};
  return d;
}

namespace {
fleet::DroneType vehicle_type(const fleet::Limits& limits) {
  fleet::DroneType type = fleet::generic_multirotor("Quad");
  type.limits = limits;
  return type;
}
}  // namespace

SimVehicle::SimVehicle(mid::EventLoop& loop, VehicleOptions options)
    : loop_(loop),
      options_(options),
      drone_(vehicle_settings(options.sysid, options.battery_percent), vehicle_type(options.limits), loop),
      encoder_{options.sysid, ml::comp::AUTOPILOT1, 0},
      dialect_(*options.dialect),
      mode_(options.boot_mode.value_or(dialect_.boot)) {}

SimVehicle::~SimVehicle() {
  link_.reset();
  for (auto& [id, timer] : streams_) loop_.cancel(timer);
  loop_.cancel(offboard_timer_);
  loop_.cancel(disarm_timer_);
  loop_.cancel(orbit_timer_);
}

// Frames cross from the link's receive thread to the loop, and only while the vehicle lives.
ml::OpenResult SimVehicle::open_link(const fleet::Endpoint& endpoint) {
  std::weak_ptr<bool> alive = alive_;
  mid::EventLoop* loop = &loop_;
  return ml::Link::open(endpoint, [this, alive, loop](ml::Frame f) {
    loop->post([this, alive, f = std::move(f)] {
      if (alive.lock()) on_frame(f);
    });
  });
}

std::string SimVehicle::open(const fleet::Endpoint& endpoint) {
  ml::OpenResult opened = open_link(endpoint);
  if (!opened.link) return opened.error;
  link_ = std::move(opened.link);
  rates_hz_[ml::msg::HEARTBEAT] = 1.0;
  send_stream(ml::msg::HEARTBEAT);
  for (uint32_t id : kStreamed) set_rate(id, options_.default_rate_hz);
  return "";
}

std::string SimVehicle::open_ground_station(const fleet::Endpoint& endpoint) {
  ml::OpenResult opened = open_link(endpoint);
  if (!opened.link) return opened.error;
  ground_station_ = std::move(opened.link);
  return "";
}

// --- input ---------------------------------------------------------------------------------

void SimVehicle::on_frame(const ml::Frame& frame) {
  if (auto c = ml::unpack_command_long(frame.message)) {
    ack_to_system_ = frame.sysid;
    ack_to_component_ = frame.compid;
    return on_command(*c);
  }
  if (auto c = ml::unpack_command_int(frame.message)) {
    ack_to_system_ = frame.sysid;
    ack_to_component_ = frame.compid;
    return on_command_int(*c);
  }
  if (auto sp = ml::unpack_set_position_target_local_ned(frame.message)) return on_setpoint(*sp);
  if (on_fence_frame(frame)) return;
  if (auto r = ml::unpack_param_request_read(frame.message)) return on_param_request(*r);
  if (auto s = ml::unpack_setup_signing(frame.message)) return on_setup_signing(*s);
  if (auto hb = ml::unpack_heartbeat(frame.message); hb && hb->autopilot == ml::autopilot::INVALID)
    heartbeat_types_.insert(hb->type);
}

// Like ArduPilot after SETUP_SIGNING: sign every frame from now on and drop every unsigned
// or badly signed one (ArduPilot lets RADIO_STATUS through unsigned; we have none). An
// all-zero key would turn signing off there; here it is ignored.
void SimVehicle::on_setup_signing(const ml::SetupSigning& s) {
  if (s.target_system != options_.sysid && s.target_system != 0) return;
  bool all_zero = true;
  for (uint8_t b : s.secret_key) all_zero = all_zero && b == 0;
  if (all_zero || !link_) return;
  ml::SigningKey key{s.secret_key};
  encoder_.signer.emplace(key, 0);
  link_->verify_with(key, true);
}

// The speed parameters the real autopilot has, valued as this vehicle flies (options.limits,
// by default the simulator's: 10 m/s across, 3 up, 2 down, 4 m/s²; it takes off without
// spool-up or ramp, and returns home at its altitude without waiting); a name it does not
// know gets no answer, like on the real ones.
void SimVehicle::on_param_request(const ml::ParamRequestRead& r) {
  if ((r.target_system != options_.sysid && r.target_system != 0) || r.param_index != -1) return;
  const fleet::Limits& l = options_.limits;
  bool px4 = dialect_.mav_autopilot == ml::autopilot::PX4;
  const std::map<std::string, double> params =
      px4 ? std::map<std::string, double>{{"MPC_XY_CRUISE", l.max_speed_mps}, {"MPC_Z_VEL_MAX_UP", l.max_climb_mps},
                                          {"MPC_TKO_SPEED", l.max_climb_mps}, {"MPC_Z_VEL_MAX_DN", l.max_descent_mps},
                                          {"MPC_LAND_SPEED", l.max_descent_mps}, {"COM_SPOOLUP_TIME", 0},
                                          {"MPC_TKO_RAMP_T", 0}, {"MPC_ACC_HOR", l.max_accel_mps2}, {"RTL_RETURN_ALT", 0}, {"RTL_LAND_DELAY", 0},
                                          {"MC_ORBIT_RAD_MAX", 1000}}
          : std::map<std::string, double>{{"WPNAV_SPEED", 100 * l.max_speed_mps},
                                          {"WPNAV_SPEED_UP", 100 * l.max_climb_mps},
                                          {"WPNAV_SPEED_DN", 100 * l.max_descent_mps},
                                          {"LAND_SPEED", 100 * l.max_descent_mps}, {"LAND_SPEED_HIGH", 0},
                                          {"MOT_SPOOL_TIME", 0}, {"TKOFF_SLEW_TIME", 0},
                                          {"WPNAV_ACCEL", 100 * l.max_accel_mps2}, {"RTL_ALT", 0},
                                          {"RTL_CLIMB_MIN", 0}, {"RTL_SPEED", 0}, {"RTL_LOIT_TIME", 0},
                                          {"RTL_ALT_FINAL", 0}};
  auto it = params.find(r.param_id);
  if (it == params.end()) return;
  int index = static_cast<int>(std::distance(params.begin(), it));
  send(ml::pack(ml::ParamValue{it->first, static_cast<float>(it->second), ml::param_type::REAL32,
                               static_cast<uint16_t>(params.size()), static_cast<uint16_t>(index)}));
}

void SimVehicle::on_command(const ml::CommandLong& c) {
  if (c.target_system != options_.sysid && c.target_system != 0) return;
  // A resend means our ACK was lost: answer again, but do not arm or take off twice.
  if (c.confirmation > 0 && has_last_ && last_command_ == c.command) return ack(c.command, last_result_);
  ++received_[c.command];
  bool arm = c.command == ml::cmd::COMPONENT_ARM_DISARM && c.param[0] > 0.5f;
  if (arm && arms_seen_++ < options_.arms_lost) return;
  if (c.command == dialect_.picture_command)
    return start_then_ack(c.command, "TakePicture", [this] {
      if (options_.camera_confirms)
        send(ml::pack(ml::CameraCapture{dialect_.picture_confirmation, pictures_taken_++, true}));
    });
  uint8_t result = execute(c);
  if (result == kAckLater) return;
  last_command_ = c.command;
  last_result_ = result;
  has_last_ = true;
  ack(c.command, result);
}

// COMMAND_INT: DO_ORBIT only, with its centre in x, y (degE7 in a global frame; INT32_MAX
// for both: where the vehicle is, as PX4 reads it). Anything else is unsupported here.
void SimVehicle::on_command_int(const ml::CommandInt& c) {
  if (c.target_system != options_.sysid && c.target_system != 0) return;
  ++received_[c.command];
  if (c.command != ml::cmd::DO_ORBIT) return ack(c.command, ml::result::UNSUPPORTED);
  ml::CommandLong as_long{c.target_system, c.target_component, c.command, 0,
                          {c.param[0], c.param[1], c.param[2], c.param[3], NAN, NAN, c.z}};
  std::optional<Vec3> centre;
  if (c.x != INT32_MAX || c.y != INT32_MAX) {
    if (!ml::is_global_frame(c.frame)) return ack(c.command, ml::result::DENIED);
    centre = Vec3{(c.y / 1e7 - kHomeLon) * kMetresPerDegree * std::cos(kHomeLat * M_PI / 180.0) - options_.east_m,
                  (c.x / 1e7 - kHomeLat) * kMetresPerDegree - options_.north_m, 0.0};
  }
  ack(c.command, start_orbit(as_long, centre));
}

uint8_t SimVehicle::execute(const ml::CommandLong& c) {
  mid::DroneState s = drone_.state();
  switch (c.command) {
    case ml::cmd::COMPONENT_ARM_DISARM: {
      bool arm = c.param[0] > 0.5f;
      if (!arm && !s.landed) return ml::result::DENIED;
      if (arm && s.battery <= 0.0) return ml::result::DENIED;
      // PX4's arming checks hold each mode's requirements: OFFBOARD's is a fresh setpoint.
      if (arm && mode_ == Mode::setpoint && dialect_.setpoints_before_switch && !setpoints_fresh())
        return ml::result::TEMPORARILY_REJECTED;
      loop_.cancel(disarm_timer_);
      start_then_ack(c.command, arm ? "Arm" : "Disarm");
      return kAckLater;
    }
    case ml::cmd::NAV_TAKEOFF: {
      if (options_.disarm_at_first_takeoff && !std::exchange(takeoff_seen_, true) && s.armed && s.landed) {
        start("Disarm", {});
        return ml::result::FAILED;
      }
      if (!s.armed || !s.landed) return ml::result::DENIED;
      if (dialect_.takeoff_in_setpoint_mode && mode_ != Mode::setpoint) return ml::result::DENIED;
      double alt = std::isnan(c.param[6]) ? 2.5 : c.param[6];
      if (dialect_.takeoff_altitude_amsl && !std::isnan(c.param[6])) alt -= options_.home_amsl_m;
      if (!(alt > 0.0) || alt > 120.0) return ml::result::DENIED;
      mode_ = Mode::takeoff;
      start("Takeoff", {alt}, dialect_.after_takeoff);
      return ml::result::ACCEPTED;
    }
    case ml::cmd::NAV_LAND: return set_mode(Mode::land);
    case ml::cmd::NAV_RETURN_TO_LAUNCH: return set_mode(Mode::rtl);
    case ml::cmd::DO_ORBIT: return start_orbit(c, std::nullopt);
    case ml::cmd::DO_SET_MODE: {
      Mode m;
      return requested_mode(c, m) ? set_mode(m) : ml::result::DENIED;
    }
    case ml::cmd::SET_MESSAGE_INTERVAL: {
      auto id = static_cast<uint32_t>(c.param[0]);
      ++intervals_asked_[id];
      if (id == ml::msg::HEARTBEAT && dialect_.heartbeat_rate_fixed) return ml::result::FAILED;
      // PX4's orbit status, sent while it orbits; ArduPilot Copter has no DO_ORBIT.
      if (!streamed(id) && !(id == ml::msg::ORBIT_EXECUTION_STATUS && dialect_.do_orbit)) return ml::result::DENIED;
      double us = c.param[1];
      set_rate(id, us < 0 ? 0.0 : us == 0 ? options_.default_rate_hz : 1e6 / us);
      return ml::result::ACCEPTED;
    }
    case ml::cmd::REQUEST_MESSAGE: {  // one now, as PX4 and ArduPilot answer it
      auto id = static_cast<uint32_t>(c.param[0]);
      if (!streamed(id)) return ml::result::DENIED;
      send(telemetry(id));
      return ml::result::ACCEPTED;
    }
  }
  return ml::result::UNSUPPORTED;
}

bool SimVehicle::requested_mode(const ml::CommandLong& c, Mode& out) const {
  auto p2 = static_cast<uint32_t>(c.param[1]), p3 = static_cast<uint32_t>(c.param[2]);
  uint32_t custom = dialect_.main_sub_modes ? (p2 << 16 | p3 << 24) : p2;
  for (int m = 0; m < kModes; ++m)
    // Takeoff and Orbit need their commands' parameters: DO_SET_MODE cannot enter them.
    if (dialect_.custom_mode[m] == custom && Mode(m) != Mode::takeoff && Mode(m) != Mode::orbit) {
      out = Mode(m);
      return true;
    }
  return false;
}

uint8_t SimVehicle::set_mode(Mode mode) {
  mid::DroneState s = drone_.state();
  switch (mode) {
    case Mode::setpoint:
      // PX4's rule: no switch to OFFBOARD unless setpoints are already streaming.
      if (dialect_.setpoints_before_switch && !setpoints_fresh()) return ml::result::DENIED;
      mode_ = Mode::setpoint;
      flying_ = false;
      if (!s.landed) start("Hover", {});  // hold until a setpoint says otherwise
      fly_to_setpoint();
      check_offboard();
      return ml::result::ACCEPTED;
    case Mode::hold:
    case Mode::manual:
      mode_ = mode;
      if (!s.landed) start("Hover", {});
      return ml::result::ACCEPTED;
    case Mode::land:
      mode_ = Mode::land;
      if (!s.landed) start("Land", {});
      return ml::result::ACCEPTED;
    case Mode::rtl:
      if (s.landed || !s.armed) return ml::result::DENIED;
      mode_ = Mode::rtl;
      start("ReturnHome", {});
      return ml::result::ACCEPTED;
    case Mode::takeoff:
    case Mode::orbit:
      break;
  }
  return ml::result::DENIED;
}

void SimVehicle::on_setpoint(const ml::SetPositionTargetLocalNed& sp) {
  if (sp.target_system != options_.sysid || sp.coordinate_frame != ml::kFrameLocalNed) return;
  setpoint_ = {sp.y, sp.x, -sp.z};  // NED -> the simulator's east, north, up
  have_setpoint_ = true;
  // Like PX4's OFFBOARD: a yaw is taken unless its ignore bit is set or it is not a number.
  setpoint_yaw_deg_.reset();
  if (!(sp.type_mask & ml::kIgnoreYawBit) && std::isfinite(sp.yaw)) {
    const double deg = std::fmod(sp.yaw * 180.0 / M_PI, 360.0);
    setpoint_yaw_deg_ = deg < 0 ? deg + 360.0 : deg;
  }
  setpoint_at_ = loop_.now();
  fly_to_setpoint();
}

void SimVehicle::start_then_ack(uint16_t command, const std::string& action, std::function<void()> after) {
  // Acknowledged once done (a picture takes 0.5 s, arming a moment), so no HEARTBEAT sent
  // after the ACK can still show the state from before.
  std::weak_ptr<bool> alive = alive_;
  drone_.start({action, {}}, [this, alive, command, after = std::move(after)](const mid::ActionEnd& end) {
    if (!alive.lock()) return;
    uint8_t result = end.outcome == mid::Outcome::succeeded ? ml::result::ACCEPTED : ml::result::FAILED;
    last_command_ = command;
    last_result_ = result;
    has_last_ = true;
    ack(command, result);
    if (command == ml::cmd::COMPONENT_ARM_DISARM && result == ml::result::ACCEPTED) send_stale_heartbeats();
    if (after && result == ml::result::ACCEPTED) after();
  });
}

void SimVehicle::send_stale_heartbeats() {
  mid::DroneState before = drone_.state();
  before.armed = !before.armed;
  for (int i = 0; i < options_.stale_heartbeats_after_arming; ++i) send(heartbeat(before));
}

void SimVehicle::fly_to_setpoint() {
  if (mode_ != Mode::setpoint || !have_setpoint_) return;
  if (flying_ && flying_to_ == setpoint_) return;
  flying_to_ = setpoint_;  // the setpoint, not where the hold stands (a stand-off is no new setpoint)
  flying_ = true;
  start("FlyTo", {setpoint_.x + options_.setpoint_standoff_east_m, setpoint_.y, setpoint_.z});
}

bool SimVehicle::setpoints_fresh() const {
  return have_setpoint_ && loop_.now() - setpoint_at_ <= options_.offboard_loss_s;
}

void SimVehicle::check_offboard() {
  loop_.cancel(offboard_timer_);
  offboard_timer_ = mid::kNoTimer;
  if (mode_ != Mode::setpoint || !dialect_.setpoint_loss_holds) return;
  if (loop_.now() - setpoint_at_ > options_.offboard_loss_s) {
    set_mode(Mode::hold);  // the companion went quiet: hold where we are
    return;
  }
  offboard_timer_ = loop_.after(0.2, [this] { check_offboard(); });
}

void SimVehicle::start(const std::string& action, std::vector<double> args,
                       std::optional<Mode> mode_after) {
  std::weak_ptr<bool> alive = alive_;
  drone_.start({action, std::move(args)}, [this, alive, action, mode_after](const mid::ActionEnd& end) {
    if (!alive.lock()) return;
    if (action == "FlyTo" && end.outcome != mid::Outcome::preempted) flying_ = false;
    if (end.outcome != mid::Outcome::succeeded) return;
    if (mode_after) mode_ = *mode_after;
    if (action == "Land" || action == "ReturnHome") after_touchdown();
    if (action == "Takeoff" && options_.hover_wander_east_m != 0.0) {
      const mid::DroneState s = drone_.state();
      start("FlyTo", {s.x + options_.hover_wander_east_m, s.y, s.z});  // until a mode or setpoint preempts it
    }
  });
}

void SimVehicle::after_touchdown() {
  loop_.cancel(disarm_timer_);
  disarm_timer_ = loop_.after(options_.disarm_after_land_s, [this] {
    disarm_timer_ = mid::kNoTimer;
    if (drone_.state().landed) start("Disarm", {});
  });
}

void SimVehicle::ack(uint16_t command, uint8_t result) {
  ml::CommandAck a;
  a.command = command;
  a.result = result;
  a.target_system = ack_to_system_;  // as PX4 does: the sender of the command
  a.target_component = ack_to_component_;
  send(ml::pack(a));
}

// --- output --------------------------------------------------------------------------------

void SimVehicle::set_rate(uint32_t id, double hz) {
  rates_hz_[id] = hz;
  if (auto it = streams_.find(id); it != streams_.end()) {
    loop_.cancel(it->second);
    streams_.erase(it);
  }
  if (hz > 0) streams_[id] = loop_.after(1.0 / hz, [this, id] { send_stream(id); });
}

void SimVehicle::send_stream(uint32_t id) {
  if (id != ml::msg::ORBIT_EXECUTION_STATUS || mode_ == Mode::orbit) send(telemetry(id));
  double hz = rates_hz_.count(id) ? rates_hz_[id] : 1.0;
  streams_[id] = loop_.after(1.0 / hz, [this, id] { send_stream(id); });
  if (id == ml::msg::HEARTBEAT) check_preflight_disarm();
}

void SimVehicle::check_preflight_disarm() {
  mid::DroneState s = drone_.state();
  if (!s.armed) {
    armed_at_.reset();
    flown_since_armed_ = false;
    return;
  }
  if (!armed_at_) armed_at_ = loop_.now();
  flown_since_armed_ = flown_since_armed_ || !s.landed;
  if (options_.preflight_disarm_s <= 0.0 || flown_since_armed_ ||
      loop_.now() - *armed_at_ < options_.preflight_disarm_s)
    return;
  armed_at_.reset();
  std::weak_ptr<bool> alive = alive_;
  drone_.start({"Disarm", {}}, [this, alive](const mid::ActionEnd& end) {
    if (!alive.lock() || end.outcome != mid::Outcome::succeeded) return;
    ml::Statustext t;
    t.severity = 6;
    t.text = "Disarmed by auto preflight disarming";
    send(ml::pack(t));
  });
}

ml::Message SimVehicle::telemetry(uint32_t id) const {
  mid::DroneState s = drone_.state();
  Vec3 v = drone_.velocity();
  switch (id) {
    case ml::msg::LOCAL_POSITION_NED: return local_position(s, v);
    case ml::msg::GLOBAL_POSITION_INT: return global_position(s, v);
    case ml::msg::ORBIT_EXECUTION_STATUS: return orbit_status(s);
    case ml::msg::EXTENDED_SYS_STATE: {
      ml::ExtendedSysState e;
      e.landed_state = s.landed                ? ml::landed::ON_GROUND
                       : mode_ == Mode::takeoff ? ml::landed::TAKEOFF
                       : mode_ == Mode::land    ? ml::landed::LANDING
                                               : ml::landed::IN_AIR;
      return ml::pack(e);
    }
    case ml::msg::SYS_STATUS: {
      ml::SysStatus st;
      st.battery_remaining = static_cast<int8_t>(std::lround(s.battery));
      return ml::pack(st);
    }
    case ml::msg::BATTERY_STATUS: {
      ml::BatteryStatus b;
      b.battery_remaining = static_cast<int8_t>(std::lround(s.battery));
      b.voltages.fill(UINT16_MAX);
      return ml::pack(b);
    }
  }
  return heartbeat(s);
}

ml::Message SimVehicle::local_position(const mid::DroneState& s, Vec3 v) const {
  v = v * options_.reported_velocity_scale;
  ml::LocalPositionNed p;
  p.time_boot_ms = static_cast<uint32_t>(s.t * 1000.0);
  p.x = static_cast<float>(s.y);
  p.y = static_cast<float>(s.x);
  p.z = static_cast<float>(-s.z);
  p.vx = static_cast<float>(v.y);
  p.vy = static_cast<float>(v.x);
  p.vz = static_cast<float>(-v.z);
  return ml::pack(p);
}

ml::Message SimVehicle::global_position(const mid::DroneState& s, Vec3 v) const {
  ml::GlobalPositionInt g;
  g.time_boot_ms = static_cast<uint32_t>(s.t * 1000.0);
  std::tie(g.lat, g.lon) = lat_lon_e7(s.x, s.y, options_.east_m, options_.north_m);
  g.vx = static_cast<int16_t>(std::lround(v.y * 100.0));
  g.vy = static_cast<int16_t>(std::lround(v.x * 100.0));
  g.vz = static_cast<int16_t>(std::lround(-v.z * 100.0));
  g.alt = static_cast<int32_t>(std::lround((options_.home_amsl_m + s.z) * 1000.0));
  g.relative_alt = static_cast<int32_t>(std::lround((s.z - options_.home_above_origin_m) * 1000.0));
  // As a real autopilot: cdeg from north, UINT16_MAX when the vehicle does not know. Flying
  // setpoints that name a heading, this vehicle turns to it at once; otherwise the
  // simulator's nose follows its velocity.
  const bool yaw_set = mode_ == Mode::setpoint && setpoint_yaw_deg_;
  const double heading = yaw_set ? *setpoint_yaw_deg_ : s.heading;
  if (std::isfinite(heading)) g.hdg = static_cast<uint16_t>(std::lround(heading * 100.0) % 36000);
  return ml::pack(g);
}

// As PX4's FlightTaskOrbit reports it: MAV_FRAME_GLOBAL, the centre in degE7.
ml::Message SimVehicle::orbit_status(const mid::DroneState& s) const {
  ml::OrbitExecutionStatus o;
  o.time_usec = static_cast<uint64_t>(s.t * 1e6);
  o.radius = static_cast<float>(-orbit_.direction * orbit_.radius);
  o.frame = 0;
  std::tie(o.x, o.y) = lat_lon_e7(orbit_.centre.x, orbit_.centre.y, options_.east_m, options_.north_m);
  o.z = static_cast<float>(options_.home_amsl_m + orbit_.centre.z);
  return ml::pack(o);
}

ml::Message SimVehicle::heartbeat(const mid::DroneState& s) const {
  ml::Heartbeat hb;
  hb.type = ml::mav_type::QUADROTOR;
  hb.autopilot = dialect_.mav_autopilot;
  hb.base_mode = ml::mode_flag::CUSTOM_MODE_ENABLED | (s.armed ? ml::mode_flag::SAFETY_ARMED : 0);
  hb.custom_mode = dialect_.custom_mode[static_cast<int>(mode_)];
  hb.system_status = s.armed ? ml::state::ACTIVE : ml::state::STANDBY;
  return ml::pack(hb);
}

void SimVehicle::send(const ml::Message& m) {
  if (!link_ && !ground_station_) return;
  std::vector<uint8_t> frame = encoder_.encode(m);
  if (link_) link_->send(frame);
  if (ground_station_) ground_station_->send(frame);
}

std::pair<double, double> SimVehicle::local_of(int32_t lat_e7, int32_t lon_e7) const { return local_xy(lat_e7, lon_e7); }

}  // namespace eamos::sim_vehicle
