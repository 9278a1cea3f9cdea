#include "sim/battery.h"

#include <algorithm>

namespace eamos::sim {

double drain_rate(bool armed, bool landed) {
  if (!armed) return kDrainDisarmed;
  return landed ? kDrainArmedOnGround : kDrainAirborne;
}

double Battery::at(double t) const {
  return std::max(0.0, percent_ - rate_ * std::max(0.0, t - since_));
}

void Battery::set_rate(double t, double rate) {
  percent_ = at(t);
  since_ = t;
  rate_ = rate;
}

double Battery::empty_at() const {
  if (rate_ <= 0.0 || percent_ <= 0.0) return std::numeric_limits<double>::infinity();
  return since_ + percent_ / rate_;
}

}  // namespace eamos::sim
