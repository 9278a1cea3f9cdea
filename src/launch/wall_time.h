#pragma once
// Wall clocks of the launch layer: Unix time (shared by every machine of a fleet whose
// clocks are synchronised, NTP or PTP) for the start instant, steady time for timeouts.
#include <chrono>
#include <cstdint>

namespace eamos::launch {

inline std::int64_t unix_ns() {
  using namespace std::chrono;
  return duration_cast<nanoseconds>(system_clock::now().time_since_epoch()).count();
}

inline double wall_s() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

}  // namespace eamos::launch
