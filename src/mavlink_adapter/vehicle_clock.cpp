#include "mavlink_adapter/vehicle_clock.h"

#include <algorithm>
#include <cstdio>

namespace eamos::mavlink_adapter {

void VehicleClock::on_report(uint32_t time_boot_ms) {
  const double vehicle_s = time_boot_ms / 1000.0;
  // A reboot (or a reordered datagram) starts the window again.
  if (!samples_.empty() && vehicle_s < samples_.back().second) samples_.clear();
  samples_.push_back({loop_.now(), vehicle_s});
  while (samples_.size() > 2 && samples_.back().first - samples_.front().first > 10.0) samples_.pop_front();
  double r = rate();
  if (r < 0.8 && !noted_) {
    noted_ = true;
    char text[160];
    std::snprintf(text, sizeof text,
                  "the vehicle's clock runs at %.2f of mission time (a SITL slower than --speed?): deadlines are "
                  "stretched to match",
                  r);
    note_(text);
  }
}

double VehicleClock::rate() const {
  if (samples_.size() < 2) return 1.0;
  double mission = samples_.back().first - samples_.front().first;
  if (mission < 2.0) return 1.0;  // too short to tell jitter from rate
  return (samples_.back().second - samples_.front().second) / mission;
}

double VehicleClock::deadline_rate() const { return std::clamp(rate(), 0.2, 1.0); }

}  // namespace eamos::mavlink_adapter
