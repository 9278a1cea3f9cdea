#pragma once
// The vehicle's clock against mission time. A SITL on a loaded machine runs slower than
// --speed; it flies as fast as ever in its own clock, so every deadline and wait of the
// adapter is stretched by how much slower (timeout_for, the link watchdog, the orbit's step).
// Measured from LOCAL_POSITION_NED's time_boot_ms over the last ten mission seconds.
#include <cstdint>
#include <deque>
#include <functional>
#include <string>
#include <utility>

#include "mid/event_loop.h"

namespace eamos::mavlink_adapter {

class VehicleClock {
 public:
  /// `note` hears, once, that the vehicle's clock runs slow.
  VehicleClock(const mid::EventLoop& loop, std::function<void(const std::string&)> note)
      : loop_(loop), note_(std::move(note)) {}

  /// Folds a position report's time_boot_ms in.
  void on_report(uint32_t time_boot_ms);
  /// Vehicle seconds per mission second over the last few seconds (1 until known).
  double rate() const;
  /// rate() as mission_s() allows for it: within 0.2 … 1.
  double deadline_rate() const;
  /// `vehicle_s` seconds of the vehicle's time in mission seconds, for a deadline or a wait:
  /// never shorter (a vehicle clock ahead of ours is jitter), at most 5 times longer.
  double mission_s(double vehicle_s) const { return vehicle_s / deadline_rate(); }

 private:
  const mid::EventLoop& loop_;
  std::function<void(const std::string&)> note_;
  std::deque<std::pair<double, double>> samples_;  ///< (mission s, vehicle s) of recent reports
  bool noted_ = false;
};

}  // namespace eamos::mavlink_adapter
