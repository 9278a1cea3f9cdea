#pragma once
// The simulated battery: a charge that drains at a constant rate per flight phase. It is
// integrated exactly between phase changes (no per-step bookkeeping), so a drone that sits
// still costs nothing however long the mission runs.
#include <limits>

namespace eamos::sim {

/// Drain in % of a full charge per second. A multirotor spends nearly all of its power
/// holding itself up, so hovering and moving drain alike.
inline constexpr double kDrainDisarmed = 0.0;
/// Motors spinning on the ground: 100 % lasts about 2.8 hours.
inline constexpr double kDrainArmedOnGround = 0.01;
/// In the air: 100 % lasts 1000 s (about 17 minutes), a typical small quadcopter.
inline constexpr double kDrainAirborne = 0.1;

double drain_rate(bool armed, bool landed);

class Battery {
 public:
  Battery(double percent, double t) : percent_(percent), since_(t) {}

  /// Charge at time t >= the last set_rate, never below 0.
  double at(double t) const;
  /// From time t on, drain at `rate` %/s (the charge up to t is kept).
  void set_rate(double t, double rate);
  /// When the charge reaches 0 at the current rate; infinity when it does not drain or is
  /// already empty.
  double empty_at() const;

 private:
  double percent_;     ///< charge at `since_`
  double since_;       ///< mission time the rate was last set
  double rate_ = 0.0;  ///< %/s
};

}  // namespace eamos::sim
