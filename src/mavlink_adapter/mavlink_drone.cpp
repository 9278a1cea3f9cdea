// The MavlinkDrone's parts wired together, and frames from the vehicle handed to them: what
// a frame changed decides which part hears of it and whether the drone's state is published.
#include "mavlink_adapter/mavlink_drone.h"

#include "mavlink/enums.h"
#include "mid/site_limits.h"
#include "mid/vec.h"

namespace eamos::mavlink_adapter {

namespace ml = eamos::mavlink;
using fleet::Vec3;
using mid::ActionId;

namespace {
constexpr uint8_t kLastMavResult = 9;  ///< MAV_RESULT_UNSUPPORTED_MAV_FRAME
}  // namespace

MavlinkDrone::MavlinkDrone(fleet::DroneSettings settings, fleet::DroneType type, mid::EventLoop& loop,
                           MavlinkOptions options)
    : AdapterDrone(loop, std::move(type)),
      settings_(std::move(settings)),
      options_(options),
      link_(settings_, loop, options_, [this](const ml::Frame& f) { on_frame(f); },
            [this](const std::string& text) { note(text); }),
      commands_(loop, [this](const ml::Message& m) { link_.send(m); }, options.commands),
      modes_(commands_),
      clock_(loop, [this](const std::string& text) { note(text); }),
      watch_(loop, options_, link_, commands_, clock_, watch_hooks()),
      stream_(loop, options_, settings_, link_, modes_, vehicle_, watch_, stream_hooks()),
      orbit_(settings_, link_, vehicle_, clock_, stream_, modes_, commands_, orbit_hooks()),
      camera_(link_, commands_, options_.picture_confirm_s, camera_hooks()) {
  keep_site(settings_);
}

MavlinkDrone::~MavlinkDrone() { link_.close(); }

LinkWatch::Hooks MavlinkDrone::watch_hooks() {
  return {.lost = [this](const std::string& why) { on_link_lost(why); },
          .back = [this] { publish(); },
          .poll_wanted = [this] { return vehicle_.landed() || orbit_.commanded(); },
          .note = [this](const std::string& text) { note(text); }};
}

SetpointStream::Hooks MavlinkDrone::stream_hooks() {
  return {.steer = [this](double dt) { return orbit_.steer(dt); },
          .refused = [this](const CommandResult& r) {
            const Autopilot& ap = *link_.autopilot();
            fail_motion(r.answered ? mid::FailureReason::refused : mid::FailureReason::timed_out,
                        std::string("switch to ") + ap.setpoint_mode_name + " refused by " + ap.name + ": " + r.error,
                        r.error);
          }};
}

OrbitFlight::Hooks MavlinkDrone::orbit_hooks() {
  return {.note = [this](const std::string& text) { note(text); },
          .refused = [this](ActionId id, const CommandResult& result) {
            if (tracker_.running(id)) end_refused(id, result);
          },
          .left = [this](const std::string& reason, const std::string& detail) {
            fail_motion(mid::FailureReason::pilot_took_over, reason, detail);
          }};
}

Camera::Hooks MavlinkDrone::camera_hooks() {
  return {.running = [this](ActionId id) { return tracker_.running(id); },
          .taken = [this](ActionId id) {
            publish();
            tracker_.end(id, mid::Outcome::succeeded);
          },
          .failed = [this](ActionId id, mid::FailureReason why, const std::string& reason,
                           const std::string& detail) { tracker_.fail(id, why, reason, detail); },
          .after = [this](ActionId id, double s, std::function<void()> fn) { after_for(id, s, std::move(fn)); },
          .clear_timer = [this](ActionId id) { clear_action_timer(id); },
          .note = [this](const std::string& text) { note(text); }};
}

std::string MavlinkDrone::connect(const fleet::Endpoint& endpoint) {
  if (std::string error = link_.connect(endpoint); !error.empty()) return error;
  watch_.start();
  const auto& fence = settings_.site.geofence;
  fence_wanted_ = fence && fence->upload && !fence->polygon.empty();
  return "";
}

// Waits for both positions: the corners are placed from the vehicle's local origin, as its
// setpoints are, so that the autopilot's fence and the companion's are the same area.
void MavlinkDrone::maybe_upload_fence() {
  if (!fence_wanted_ || fence_ || !vehicle_.have_position || !vehicle_.have_altitude) return;
  const Autopilot& ap = *link_.autopilot();
  auto [lat, lon] = offset_lat_lon(vehicle_.lat_e7, vehicle_.lon_e7, -vehicle_.ned.x, -vehicle_.ned.y);
  AutopilotFence fence = autopilot_fence(ap, *settings_.site.geofence, settings_.home, settings_.failsafe,
                                         GlobalOrigin{lat, lon}, link_.sysid());
  fence_ = std::make_unique<FenceUpload>(
      loop_, ap,
      FenceUpload::Hooks{.send = [this](const ml::Message& m) { link_.send(m); },
                         .note = [this](const std::string& text) { note(text); }},
      FenceUpload::Options{options_.fence_reply_s, options_.fence_attempts});
  fence_->start(std::move(fence), link_.sysid(), [this](const std::string& error) {
    if (!error.empty()) note("fence upload failed: " + error);
    auto waiting = std::move(after_fence_);
    after_fence_.clear();
    for (auto& fn : waiting) fn();
  });
}

void MavlinkDrone::on_frame(const ml::Frame& frame) {
  if (frame.sysid != link_.sysid()) return;  // another vehicle (or a GCS) on the same port
  if (fence_ && frame.compid == ml::comp::AUTOPILOT1) fence_->on_message(frame.message);
  if (auto ack = ml::unpack_command_ack(frame.message)) {
    // MAV_RESULT ends at 9 (UNSUPPORTED_MAV_FRAME): an unknown result answers nothing;
    // the command is sent again and times out as unanswered if it never gets a real one.
    if (ack->result > kLastMavResult) return link_.note_rejected("COMMAND_ACK with an unknown result");
    // An ACK addressed to another component (a GCS commanding the same vehicle) is not ours;
    // 0 means the autopilot did not say (older firmware).
    if (ack->target_component == 0 || ack->target_component == ml::comp::ONBOARD_COMPUTER)
      commands_.on_ack(*ack);
    return;
  }
  // From the autopilot or from a camera component of the same system.
  if (auto capture = ml::unpack_camera_capture(frame.message)) return camera_.on_capture(*capture);
  if (auto hb = ml::unpack_heartbeat(frame.message); hb && hb->autopilot == ml::autopilot::INVALID)
    return;  // a camera, gimbal or companion of the same system: not the autopilot
  if (auto t = ml::unpack_statustext(frame.message); t && frame.compid == ml::comp::AUTOPILOT1) {
    for (const std::string& text : texts_.add(*t, loop_.now(), link_.autopilot()->name)) note(text);
    return;
  }
  if (auto report = ml::unpack_local_position_ned(frame.message)) clock_.on_report(report->time_boot_ms);
  Changes c = apply_telemetry(vehicle_, frame);
  if (c.rejected) return link_.note_rejected(c.rejected);
  if (c.armed_unconfirmed)
    note(std::string("a HEARTBEAT after the autopilot accepted the ") + (vehicle_.armed ? "ARM" : "DISARM") +
         " still said " + (vehicle_.armed ? "disarmed" : "armed") +
         " (made before the command took effect, or the vehicle changed at once): the next one decides");
  if (c.armed) on_armed_changed();
  if (c.heartbeat) on_heartbeat();
  if (c.landed && vehicle_.landed()) {
    stream_.hand_over();  // on the ground: nothing to hold
    disarm_after_failsafe_landing();
  }
  if (c.position || c.landed) check_goal();
  if (c.global_position) orbit_.on_global_position();
  if (c.position || c.global_position) maybe_upload_fence();
  if (c.armed || c.landed) end_motion_on_the_ground();
  if (c.position || c.armed || c.landed) publish();
}

void MavlinkDrone::on_heartbeat() {
  for (const std::string& text : texts_.flush(loop_.now(), link_.autopilot()->name)) note(text);
  link_.note_foreign();
  watch_.on_heartbeat();
  if (orbit_.on_heartbeat()) return;
  if (!stream_.taken_away()) return;
  const Autopilot& ap = *link_.autopilot();
  std::string mode = mode_name(ap, vehicle_.custom_mode);
  fail_motion(mid::FailureReason::pilot_took_over, std::string("the vehicle left ") + ap.setpoint_mode_name + " for " + mode,
              "mode " + mode);
}

void MavlinkDrone::on_link_lost(const std::string& why) {
  stream_.hand_over();
  fail_all(mid::FailureReason::link_lost, why);
  commands_.fail_all("link lost");
  publish();
}

std::string MavlinkDrone::autopilot_says(double since) const { return texts_.says(since, link_.autopilot()->name); }

void MavlinkDrone::note(const std::string& text) {
  if (message_sink_) message_sink_(text);
}

// --- properties ----------------------------------------------------------------------------

Vec3 MavlinkDrone::reference() const {
  if (holding_ && mid::LocationValidator(*holding_, settings_.tolerance).reached(position())) return *holding_;
  return position();
}

double MavlinkDrone::sensor_value(int k) const {
  auto it = settings_.sensors.find("Sensor" + std::to_string(k));
  if (it == settings_.sensors.end()) return 0.0;
  return it->second.base + dot(it->second.gradient, position());
}

mid::DroneState MavlinkDrone::state() const {
  mid::DroneState s;
  s.t = loop_.now();
  Vec3 p = position();
  s.x = p.x;
  s.y = p.y;
  s.z = p.z;
  s.battery = vehicle_.battery >= 0 ? vehicle_.battery : settings_.battery_percent;
  s.armed = vehicle_.armed;
  s.landed = vehicle_.landed();
  for (int k = 1; k <= type_.sensors; ++k) s.sensors["Sensor" + std::to_string(k)] = sensor_value(k);
  s.pictures = camera_.pictures();
  if (vehicle_.heading_deg >= 0) s.heading = vehicle_.heading_deg;
  if (link_.autopilot() && vehicle_.heard) s.mode = mode_name(*link_.autopilot(), vehicle_.custom_mode);
  s.link_lost = watch_.lost();
  return s;
}

mid::SubscriptionId MavlinkDrone::subscribe(mid::StateCallback fn) { return broker_.subscribe(std::move(fn)); }

void MavlinkDrone::publish() {
  mid::DroneState s = state();
  watch_site(s);
  if (!broker_.empty()) broker_.publish(s);
}

}  // namespace eamos::mavlink_adapter
