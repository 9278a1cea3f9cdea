#pragma once
// The LocationValidator (paper, section VI): has a drone reached a target location? Real
// vehicles never stop exactly on a setpoint, so "reached" means within a tolerance, with
// separate horizontal and vertical bounds (altitude estimates are noisier than position).
// The bounds are the type's goal tolerance from the fleet file; its speed bound is the
// caller's to judge (a position says nothing of it).
#include "fleet/fleet.h"

namespace eamos::mid {

class LocationValidator {
 public:
  explicit LocationValidator(fleet::Vec3 target, fleet::GoalTolerance tolerance = {})
      : target_(target), tolerance_(tolerance) {}

  /// True when `position` is within the tolerance of the target (bounds inclusive).
  bool reached(fleet::Vec3 position) const;
  const fleet::Vec3& target() const { return target_; }

 private:
  fleet::Vec3 target_;
  fleet::GoalTolerance tolerance_;
};

}  // namespace eamos::mid
