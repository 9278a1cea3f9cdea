#include "mid/location_validator.h"

#include <cmath>

#include "mid/vec.h"

namespace eamos::mid {

bool LocationValidator::reached(fleet::Vec3 position) const {
  fleet::Vec3 d = position - target_;
  return horizontal_norm(d) <= tolerance_.horizontal_m && std::abs(d.z) <= tolerance_.vertical_m;
}

}  // namespace eamos::mid
