#pragma once
// The LocationValidator (paper, section VI): has a drone reached a target location? Real
// vehicles never stop exactly on a setpoint, so "reached" means within a tolerance, with
// separate horizontal and vertical bounds (altitude estimates are noisier than position).
#include "fleet/fleet.h"

namespace eamos::mid {

struct Tolerance {
  double horizontal_m = 0.5;  ///< radius around the target in the x/y plane
  double vertical_m = 0.3;    ///< band above and below the target's z
};

class LocationValidator {
 public:
  explicit LocationValidator(fleet::Vec3 target, Tolerance tolerance = {})
      : target_(target), tolerance_(tolerance) {}

  /// True when `position` is within the tolerance of the target (bounds inclusive).
  bool reached(fleet::Vec3 position) const;
  const fleet::Vec3& target() const { return target_; }

 private:
  fleet::Vec3 target_;
  Tolerance tolerance_;
};

}  // namespace eamos::mid
