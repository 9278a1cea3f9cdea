#include "sim/sim_drone.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "mid/requests.h"
#include "mid/site_limits.h"
#include "mid/timeouts.h"
#include "mid/vec.h"

namespace eamos::sim {

using fleet::Vec3;
using mid::ActionId;
using mid::Outcome;

using mid::metres;

SimDrone::SimDrone(fleet::DroneSettings settings, fleet::DroneType type, mid::EventLoop& loop,
                   SimOptions options)
    : AdapterDrone(loop, std::move(type)),
      settings_(std::move(settings)),
      options_(options),
      battery_(settings_.battery_percent, loop.now()) {
  kin_.position = settings_.home;
  // The site's speed limits are the ones it flies by (and derives its deadlines from).
  settings_.limits = mid::flight_limits(settings_);
  keep_site(settings_);
  if (settings_.gust) gust_timer_ = loop_.at(settings_.gust->at_s, [this] { gust_changed(); });
  for (int k = 1; k <= type_.sensors; ++k) {
    std::string name = "Sensor" + std::to_string(k);
    auto it = settings_.sensors.find(name);
    sensor_models_.push_back({name, it == settings_.sensors.end() ? nullptr : &it->second});
    sensor_names_.emplace_hint(sensor_names_.end(), name, 0.0);
  }
  // In the names' order (Sensor10 before Sensor2), as a state lists them.
  for (auto& [name, reading] : sensor_names_) {
    auto it = settings_.sensors.find(name);
    const fleet::SensorModel* m = it == settings_.sensors.end() ? nullptr : &it->second;
    sensor_names_models_.push_back(m);
    if (!m) continue;
    reading = m->base;
    // base + 0·position is base, except that -0 + 0 is +0: such a sensor is worked out per step.
    const fleet::Vec3& g = m->gradient;
    sensors_vary_ |= g.x != 0.0 || g.y != 0.0 || g.z != 0.0 || (m->base == 0.0 && std::signbit(m->base));
  }
  published_.sensors = sensor_names_;
}

SimDrone::~SimDrone() {
  for (mid::TimerId t : {step_timer_, telemetry_timer_, empty_timer_, publish_timer_, gust_timer_})
    loop_.cancel(t);
}

// --- actions -------------------------------------------------------------------------------

double SimDrone::timeout_for(const mid::ActionRequest& r) const {
  return mid::action_timeout(r, kin_.position, settings_);
}

std::string SimDrone::refusal(const mid::ActionRequest& r, const fleet::ActionSpec& spec) const {
  if (r.name == "Arm" && battery_.at(loop_.now()) <= 0.0) return "battery empty: cannot arm";
  mid::VehicleFacts v{armed_, landed_, kin_.position, ""};
  if (tracker_.motion() != mid::kNoAction) v.running_motion = tracker_.request(tracker_.motion())->name;
  return mid::uniform_refusal(r, spec, v, settings_);
}

void SimDrone::start_system(ActionId id, const mid::ActionRequest& r) {
  // The autopilot acknowledges at once, but the change and the end both come from the loop:
  // nothing a subscriber sees may happen inside start().
  bool arm = r.name == "Arm";
  after_for(id, 0.0, [this, id, arm] {
    set_armed(arm);
    publish();
    tracker_.end(id, Outcome::succeeded);
    update_timers();
  });
}

void SimDrone::start_payload(ActionId id, const mid::ActionRequest& r) {
  double duration = r.name == "TakePicture" ? options_.picture_s : options_.sensor_read_s;
  after_for(id, duration, [this, id, name = r.name] { finish_payload(id, name); });
}

void SimDrone::finish_payload(ActionId id, const std::string& name) {
  if (name == "TakePicture") {
    ++pictures_;
    publish();
    tracker_.end(id, Outcome::succeeded);
    return;
  }
  // The reading is taken where the drone is when the read completes.
  int k = fleet::sensor_index(name, type_.sensors);
  tracker_.end(id, Outcome::succeeded, "", sensor_value(k));
}

void SimDrone::start_motion(ActionId id, const mid::ActionRequest& r) {
  motion_owner_ = id;
  held_motion_.reset();
  const Vec3 here = kin_.position;
  Motion m;
  m.ground_z = ground_z();
  if (auto goal = mid::goal_position(r, here, settings_.home)) {
    if (r.name == "Land") {
      if (landed_) {  // already down: nothing to fly
        motion_owner_ = mid::kNoAction;
        stop_motion();
        tracker_.end(id, Outcome::succeeded);
        return;
      }
      m.kind = MotionKind::land;
      m.target = *goal;
      // Like an autopilot, a drone told to land while moving brakes first and lands where
      // it comes to rest, rather than flying back to where the command found it.
      const fleet::Vec3& v = kin_.velocity;
      double speed = std::sqrt(v.x * v.x + v.y * v.y);
      double accel = settings_.limits.max_accel_mps2;
      if (speed > 0 && accel > 0) {
        double stop = speed / (2.0 * accel);  // distance / speed: d = v² / 2a
        m.target.x += v.x * stop;
        m.target.y += v.y * stop;
      }
    } else if (r.name == "ReturnHome") {
      // Back at the altitude it flies at, then straight down onto home.
      m.kind = MotionKind::go;
      m.target = {goal->x, goal->y, here.z};
      m.land_after = true;
      m.ground_z = goal->z;
    } else {
      m.kind = MotionKind::go;
      m.target = *goal;
    }
    motion_ = m;
    motion_.start_distance = remaining_distance(motion_, here);
    return;
  }
  if (r.name == "Orbit") {
    m.kind = MotionKind::orbit;
    m.target = here;
    m.radius = r.args.empty() ? 5.0 : r.args[0];
    motion_ = m;
    return;
  }
  // Hover: brake to a stop where it is and stay; Hover(s) ends after s seconds.
  stop_motion();
  motion_owner_ = id;
  if (r.args.size() == 1) {
    after_for(id, r.args[0], [this, id] {
      if (motion_owner_ == id) motion_owner_ = mid::kNoAction;
      tracker_.end(id, Outcome::succeeded);
    });
  }
}

void SimDrone::stop_action(ActionId id) {
  if (id == motion_owner_) {
    motion_owner_ = mid::kNoAction;
    held_motion_.reset();
    stop_motion();
  }
  update_timers();
}

bool SimDrone::hold_vehicle(ActionId id, double climb_m) {
  if (id != motion_owner_ || (motion_.kind != MotionKind::go && motion_.kind != MotionKind::land)) return false;
  held_motion_ = motion_;
  // Where braking at full deceleration ends: a hold at the current point would overshoot
  // it and fly back, towards the drone it gives way to.
  const Vec3& v = kin_.velocity;
  const double accel = settings_.limits.max_accel_mps2;
  const double stop = accel > 0 ? std::sqrt(v.x * v.x + v.y * v.y) / (2.0 * accel) : 0.0;
  motion_ = Motion{};
  motion_.kind = MotionKind::hold;
  motion_.ground_z = ground_z();
  motion_.target = {kin_.position.x + v.x * stop, kin_.position.y + v.y * stop,
                    std::max(ground_z(), kin_.position.z + climb_m)};
  update_timers();
  return true;
}

void SimDrone::resume_vehicle(ActionId id) {
  if (id != motion_owner_ || !held_motion_) return;
  motion_ = *held_motion_;
  held_motion_.reset();
  update_timers();
}

double SimDrone::distance_left(ActionId id) const {
  const Motion& m = held_motion_ ? *held_motion_ : motion_;
  if (id != motion_owner_ || (m.kind != MotionKind::go && m.kind != MotionKind::land))
    return std::numeric_limits<double>::quiet_NaN();
  const Vec3 d = m.target - kin_.position;
  return std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
}

std::optional<Vec3> SimDrone::goal_of(mid::ActionId id) const {
  const Motion& m = held_motion_ ? *held_motion_ : motion_;
  if (id != motion_owner_ || (m.kind != MotionKind::go && m.kind != MotionKind::land)) return std::nullopt;
  return m.target;
}

void SimDrone::stop_motion() {
  bool still = kin_.velocity == Vec3{};
  motion_ = Motion{};
  motion_.ground_z = ground_z();
  if (!still) {
    motion_.kind = MotionKind::hold;
    motion_.target = kin_.position;
  }
}

std::optional<double> SimDrone::progress(ActionId id) const {
  const mid::ActionRequest* r = tracker_.request(id);
  if (!r || mid::is_endless(*r)) return std::nullopt;
  double elapsed = loop_.now() - tracker_.started_at(id);
  double fraction = 0.0;
  if (id == motion_owner_ && motion_.start_distance > 0.0) {
    fraction = 1.0 - remaining_distance(motion_, kin_.position) / motion_.start_distance;
  } else if (r->name == "Hover") {
    fraction = r->args[0] > 0.0 ? elapsed / r->args[0] : 1.0;
  } else if (r->name == "TakePicture") {
    fraction = elapsed / options_.picture_s;
  } else if (fleet::sensor_index(r->name, type_.sensors) > 0) {
    fraction = elapsed / options_.sensor_read_s;
  }
  return std::clamp(fraction, 0.0, 1.0);
}

// --- failsafe ------------------------------------------------------------------------------

void SimDrone::failsafe(fleet::Failsafe what) {
  enter_failsafe(what, {Outcome::cancelled, std::string("failsafe: ") + fleet::failsafe_name(what)});
}

void SimDrone::enter_failsafe(fleet::Failsafe what, const mid::ActionEnd& end) {
  refuse_from_now(end.reason);
  end_all(end);
  motion_owner_ = mid::kNoAction;
  held_motion_.reset();
  if (landed_) {
    // On the ground every failsafe means the same: motors off.
    stop_motion();
    if (armed_) {
      set_armed(false);
      post_publish();
    }
  } else if (what == fleet::Failsafe::hover) {
    stop_motion();
  } else {
    Motion m;
    m.ground_z = ground_z();
    if (what == fleet::Failsafe::land) {
      m.kind = MotionKind::land;
      m.target = {kin_.position.x, kin_.position.y, ground_z()};
    } else {
      m.kind = MotionKind::go;
      m.target = {settings_.home.x, settings_.home.y, kin_.position.z};
      m.land_after = true;
    }
    m.start_distance = remaining_distance(m, kin_.position);
    motion_ = m;
  }
  update_timers();
}

void SimDrone::battery_empty() {
  empty_timer_ = mid::kNoTimer;
  // What an autopilot does at critical charge: fail what it was doing and land where it is.
  char detail[64];
  std::snprintf(detail, sizeof detail, "battery at %.1f %%", battery_.at(loop_.now()));
  enter_failsafe(fleet::Failsafe::land, {.outcome = Outcome::failed, .reason = "battery empty",
                                         .failure = mid::FailureReason::vehicle_fault, .detail = detail});
  publish();
}

// --- the model -----------------------------------------------------------------------------

void SimDrone::step() {
  step_timer_ = mid::kNoTimer;
  ++steps_;
  const double dt = 1.0 / options_.step_hz;
  StepEvent event = step_motion(motion_, kin_, settings_.limits, dt);
  // A step covers (now - dt, now]: the gust moves the drone on every step that ends in its window.
  const auto& g = settings_.gust;
  if (g && !landed_ && loop_.now() > g->at_s + 1e-9 && loop_.now() <= g->at_s + g->for_s + 1e-9)
    kin_.position = kin_.position + g->velocity * dt;
  if (kin_.position.z < ground_z()) {  // the ground stops a braking descent
    kin_.position.z = ground_z();
    kin_.velocity.z = std::max(0.0, kin_.velocity.z);
  }
  if (landed_ && kin_.position.z > ground_z()) set_landed(false);
  // The nose follows the horizontal velocity; a drone (nearly) standing keeps its heading.
  if (std::hypot(kin_.velocity.x, kin_.velocity.y) > 0.1) {
    double deg = std::atan2(kin_.velocity.x, kin_.velocity.y) * 180.0 / M_PI;
    heading_ = deg < 0 ? deg + 360.0 : deg;
  }

  ActionId owner = motion_owner_;
  if (event == StepEvent::arrived || event == StepEvent::touched_down) motion_owner_ = mid::kNoAction;
  if (event == StepEvent::touched_down) {
    set_landed(true);
    if (!failsafe_reason_.empty()) set_armed(false);  // a failsafe ends with motors off
  }
  publish();
  if ((event == StepEvent::arrived || event == StepEvent::touched_down) && owner != mid::kNoAction)
    tracker_.end(owner, Outcome::succeeded);
  update_timers();
}

void SimDrone::set_armed(bool armed) {
  if (armed_ == armed) return;
  armed_ = armed;
  phase_changed();
}

void SimDrone::set_landed(bool landed) {
  if (landed_ == landed) return;
  landed_ = landed;
  phase_changed();
}

void SimDrone::phase_changed() {
  battery_.set_rate(loop_.now(), drain_rate(armed_, landed_));
  loop_.cancel(empty_timer_);
  empty_timer_ = mid::kNoTimer;
  // Only in the air does an empty battery force anything (a landing); on the ground the
  // charge just stops at 0 and the next Arm is refused.
  if (armed_ && !landed_) empty_timer_ = loop_.at(battery_.empty_at(), [this] { battery_empty(); });
}

bool SimDrone::gust_blows() const {
  const auto& g = settings_.gust;
  // Through the window's last instant: its last step ends there.
  return g && !landed_ && loop_.now() >= g->at_s && loop_.now() <= g->at_s + g->for_s + 1e-9;
}

void SimDrone::gust_changed() {
  gust_timer_ = mid::kNoTimer;
  if (loop_.now() <= settings_.gust->at_s)
    gust_timer_ = loop_.at(settings_.gust->at_s + settings_.gust->for_s, [this] { gust_changed(); });
  update_timers();
}

void SimDrone::update_timers() {
  bool moving = motion_.kind != MotionKind::idle || gust_blows();
  if (moving && step_timer_ == mid::kNoTimer) {
    // A run of steps starts one step from now; its later steps are counted from that origin,
    // so their times do not drift by rounding.
    if (steps_in_run_ == 0) steps_origin_ = loop_.now();
    ++steps_in_run_;
    step_timer_ = loop_.at(steps_origin_ + steps_in_run_ / options_.step_hz, [this] { step(); });
  } else if (!moving) {
    loop_.cancel(step_timer_);
    step_timer_ = mid::kNoTimer;
    steps_in_run_ = 0;
  }

  bool idle_telemetry = armed_ && !moving && !broker_.empty() && options_.idle_telemetry_hz > 0;
  if (idle_telemetry && telemetry_timer_ == mid::kNoTimer) {
    telemetry_timer_ = loop_.after(1.0 / options_.idle_telemetry_hz, [this] {
      telemetry_timer_ = mid::kNoTimer;
      publish();
      update_timers();
    });
  } else if (!idle_telemetry) {
    loop_.cancel(telemetry_timer_);
    telemetry_timer_ = mid::kNoTimer;
  }
}

// --- properties ----------------------------------------------------------------------------

double SimDrone::sensor_value(int k) const {
  if (k < 1 || k > static_cast<int>(sensor_models_.size())) {
    auto it = settings_.sensors.find("Sensor" + std::to_string(k));
    return it == settings_.sensors.end() ? 0.0 : it->second.base + dot(it->second.gradient, kin_.position);
  }
  const fleet::SensorModel* m = sensor_models_[k - 1].second;
  return m ? m->base + dot(m->gradient, kin_.position) : 0.0;
}

mid::DroneState SimDrone::state() const {
  mid::DroneState s;
  s.sensors = sensor_names_;  // the names copied in one go, in order: none is compared or built
  fill_state(s);
  return s;
}

void SimDrone::fill_state(mid::DroneState& s) const {
  s.t = loop_.now();
  s.x = kin_.position.x;
  s.y = kin_.position.y;
  s.z = kin_.position.z;
  s.battery = battery_.at(loop_.now());
  s.armed = armed_;
  s.landed = landed_;
  // Constant readings are in every state from the start (sensor_names_): a motion step
  // touches no sensor then.
  if (sensors_vary_) {
    auto model = sensor_names_models_.begin();
    for (auto& reading : s.sensors) {
      const fleet::SensorModel* m = *model++;
      reading.second = m ? m->base + dot(m->gradient, kin_.position) : 0.0;
    }
  }
  s.pictures = pictures_;
  s.heading = heading_;
  write_mode(s.mode);
}

void SimDrone::write_mode(std::string& mode) const {
  // The simulator has no autopilot modes: its mode is what its motors do, and whether a
  // failsafe took over. Written into the string the state already holds: no new string per step.
  static const char* const kinds[] = {"idle", "hold", "go", "land", "orbit"};
  const char* kind = kinds[static_cast<int>(motion_.kind)];
  if (failsafe_reason_.empty()) {
    mode.assign(kind);
    return;
  }
  mode.assign("failsafe ");
  mode.append(kind);
}

mid::SubscriptionId SimDrone::subscribe(mid::StateCallback fn) {
  mid::SubscriptionId id = broker_.subscribe(std::move(fn));
  update_timers();
  return id;
}

void SimDrone::unsubscribe(mid::SubscriptionId id) {
  broker_.unsubscribe(id);
  update_timers();
}

void SimDrone::publish() {
  if (broker_.empty() && !watches_site()) return;
  if (publishing_) return hand_out(state());  // from inside a subscriber: published_ is in use
  publishing_ = true;
  fill_state(published_);
  hand_out(published_);
  publishing_ = false;
}

void SimDrone::hand_out(const mid::DroneState& s) {
  watch_site(s);
  if (!broker_.empty()) broker_.publish(s);
}

void SimDrone::post_publish() {
  if (publish_timer_ != mid::kNoTimer) return;
  publish_timer_ = loop_.after(0.0, [this] {
    publish_timer_ = mid::kNoTimer;
    publish();
  });
}

}  // namespace eamos::sim
