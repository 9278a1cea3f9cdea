#include "mavlink_adapter/setpoint_stream.h"

#include "mavlink/enums.h"
#include "mid/site_limits.h"

namespace eamos::mavlink_adapter {

namespace ml = eamos::mavlink;
using fleet::Vec3;

SetpointStream::SetpointStream(mid::EventLoop& loop, const MavlinkOptions& options,
                               const fleet::DroneSettings& settings, VehicleLink& link, ModeCommands& modes,
                               const VehicleState& vehicle, const LinkWatch& watch, Hooks hooks)
    : loop_(loop),
      options_(options),
      settings_(settings),
      link_(link),
      modes_(modes),
      vehicle_(vehicle),
      watch_(watch),
      hooks_(std::move(hooks)),
      pacer_(mid::flight_limits(settings),
             settings.site.max_speed_mps || settings.site.max_climb_mps || settings.site.max_descent_mps) {}

SetpointStream::~SetpointStream() { loop_.cancel(timer_); }

void SetpointStream::start() {
  streaming_ = true;
  if (timer_ != mid::kNoTimer) return;
  sent_ = 0;
  pacer_.restart(mission_position(vehicle_, settings_.home));
  tick();
}

void SetpointStream::tick() {
  timer_ = mid::kNoTimer;
  if (!streaming_ || watch_.lost()) return;
  const double dt = 1.0 / options_.setpoint_hz;
  std::optional<double> yaw = hooks_.steer(dt);
  ml::SetPositionTargetLocalNed sp;
  sp.time_boot_ms = static_cast<uint32_t>(loop_.now() * 1000.0);
  sp.target_system = link_.sysid();
  sp.target_component = ml::comp::AUTOPILOT1;
  sp.coordinate_frame = ml::kFrameLocalNed;
  sp.type_mask = ml::kPositionOnlyMask;
  Vec3 ned = mission_to_ned(pacer_.next(setpoint_, dt), settings_.home);
  sp.x = static_cast<float>(ned.x);
  sp.y = static_cast<float>(ned.y);
  sp.z = static_cast<float>(ned.z);
  if (yaw) {
    sp.type_mask = ml::kPositionAndYawMask;
    sp.yaw = static_cast<float>(*yaw);
  }
  link_.send(ml::pack(sp));
  ++sent_;
  if (!in_control_ && !modes_.pending() &&
      (!link_.autopilot()->stream_before_switch || sent_ >= options_.setpoints_before_switch))
    switch_to_setpoint_mode();
  timer_ = loop_.after(dt, [this] { tick(); });
}

void SetpointStream::switch_to_setpoint_mode() {
  const Autopilot& ap = *link_.autopilot();
  if (vehicle_.custom_mode == ap.setpoint_mode) {
    in_control_ = true;
    mode_confirmed_ = true;
    return;
  }
  auto p = set_mode_params(ap, ap.setpoint_mode);
  modes_.send(link_.command(ml::cmd::DO_SET_MODE, {p[0], p[1], p[2]}), [this](const CommandResult& r) {
    if (r.accepted) {
      in_control_ = true;
      mode_confirmed_ = false;
      mode_granted_at_ = loop_.now();
      return;
    }
    streaming_ = false;
    hooks_.refused(r);
  });
}

bool SetpointStream::taken_away() {
  if (!streaming_ || !in_control_ || modes_.pending()) return false;
  if (vehicle_.custom_mode == link_.autopilot()->setpoint_mode) {
    mode_confirmed_ = true;
    return false;
  }
  // mode_confirm_s (about 3 s) without the mode we were granted: it never took effect.
  if (!mode_confirmed_ && loop_.now() - mode_granted_at_ < options_.mode_confirm_s) return false;
  // Someone else (a pilot's switch, the autopilot's own failsafe) took the vehicle out of
  // the setpoint mode: give way instead of switching back.
  hand_over();
  return true;
}

}  // namespace eamos::mavlink_adapter
