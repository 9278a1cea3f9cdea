#include "dex/mission.h"

namespace eamos::dex {

int Mission::find(int meg, int drone) const {
  auto it = index.find(key(meg, drone));
  return it == index.end() ? -1 : it->second;
}

}  // namespace eamos::dex
