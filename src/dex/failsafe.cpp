#include "dex/failsafe.h"

namespace eamos::dex {

bool command_failsafe(mid::Drone& drone, const fleet::DroneSettings& settings) {
  mid::DroneState s = drone.state();
  if (down_and_disarmed(s)) return false;  // already safe; an armed drone on the ground is disarmed
  drone.failsafe(settings.failsafe);
  return true;
}

void record_failsafe(const fleet::DroneSettings& settings, double t, const std::string& reason, TraceSink* trace) {
  if (!trace) return;
  TraceEvent e;
  e.t = t;
  e.drone = settings.name;
  e.event = "failsafe";
  e.name = fleet::failsafe_name(settings.failsafe);
  e.reason = reason;
  trace->record(e);
}

bool failsafe_over(const mid::DroneState& s, fleet::Failsafe failsafe, double waited_s, double disarmed_s) {
  if (down_and_disarmed(s) || s.link_lost || waited_s >= kFailsafeWaitLimitS) return true;
  if (!s.armed && disarmed_s >= kDisarmedSettleS) return true;
  // On the ground every failsafe disarms: that is still to come for an armed drone there.
  return failsafe == fleet::Failsafe::hover && !s.landed;
}

void enter_failsafe(mid::Drone& drone, const fleet::DroneSettings& settings, double t, const std::string& reason,
                    TraceSink* trace) {
  // Command first: a trace write (a DDS sample, a pipe) may block, the drone must not wait.
  if (command_failsafe(drone, settings)) record_failsafe(settings, t, reason, trace);
}

void abandon_drones(const std::vector<FailsafeDrone>& drones, double t, const std::string& reason,
                    TraceSink* trace, const std::function<void()>& between) {
  for (const FailsafeDrone& d : drones) d.engine->halt();
  std::vector<bool> commanded(drones.size());
  for (std::size_t i = 0; i < drones.size(); ++i) commanded[i] = command_failsafe(*drones[i].drone, *drones[i].settings);
  if (between) between();
  for (std::size_t i = 0; i < drones.size(); ++i)
    if (commanded[i]) record_failsafe(*drones[i].settings, t, reason, trace);
}

FailsafeWait::FailsafeWait(mid::EventLoop& loop, std::vector<FailsafeDrone> drones, double period_s,
                           std::function<void()> on_over, TraceSink* trace)
    : loop_(loop), drones_(std::move(drones)), period_s_(period_s), on_over_(std::move(on_over)), trace_(trace) {}

FailsafeWait::~FailsafeWait() { loop_.cancel(next_); }

void FailsafeWait::start() {
  since_ = loop_.now();
  disarmed_since_.assign(drones_.size(), -1.0);
  commanded_.assign(drones_.size(), false);
  for (std::size_t i = 0; i < drones_.size(); ++i) commanded_[i] = !down_and_disarmed(drones_[i].drone->state());
  loop_.cancel(next_);
  next_ = loop_.after(0.0, [this] { look(); });
}

// A look that finds a drone still in its failsafe comes back later rather than waiting on
// the loop: a real-time loop would otherwise wait for input until its limit, and a MAVLink
// drone's heartbeats never leave it idle.
void FailsafeWait::look() {
  next_ = mid::kNoTimer;
  const double now = loop_.now();
  fail_over_armed(now);
  for (std::size_t i = 0; i < drones_.size(); ++i) {
    bool armed = drones_[i].drone->state().armed;
    if (armed) disarmed_since_[i] = -1.0;
    else if (disarmed_since_[i] < 0) disarmed_since_[i] = now;
  }
  for (std::size_t i = 0; i < drones_.size(); ++i) {
    const FailsafeDrone& d = drones_[i];
    double disarmed_s = disarmed_since_[i] < 0 ? 0.0 : now - disarmed_since_[i];
    if (!failsafe_over(d.drone->state(), d.settings->failsafe, now - since_, disarmed_s)) {
      next_ = loop_.after(period_s_, [this] { look(); });
      return;
    }
  }
  on_over_();
}

void FailsafeWait::fail_over_armed(double now) {
  std::vector<FailsafeDrone> armed;
  for (std::size_t i = 0; i < drones_.size(); ++i)
    if (!commanded_[i] && drones_[i].drone->state().armed) {
      commanded_[i] = true;
      armed.push_back(drones_[i]);
    }
  if (!armed.empty()) abandon_drones(armed, now, "armed after the mission was abandoned", trace_);
}

}  // namespace eamos::dex
