#pragma once
// The pairwise checks of a flight (separation, occupied spots) in time linear in the samples:
// one sweep over every drone's track in time order, with the drones bucketed in a grid of
// cells at least the horizontal separation wide, so a drone is compared only with the drones
// in its cell and the eight around it (no nearer pair can be farther apart than one cell).
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "dex/runner.h"
#include "fleet/fleet.h"

namespace eamos::verify {

/// Drones bucketed by horizontal position in square cells.
class Grid {
 public:
  explicit Grid(double cell, int drones);
  /// Puts `drone` at (x, y); a drone at a position that is not finite is left out (it is near
  /// no one). Moving it again takes it out of its old cell.
  void place(int drone, double x, double y);
  void remove(int drone);
  /// Every drone in the cell of (x, y) and the eight around it (`drone` itself included when
  /// it is there), in no particular order.
  void around(double x, double y, std::vector<int>& out) const;

 private:
  std::uint64_t index(double v) const;  ///< the cell's column (or row), offset to be positive
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;
  std::vector<std::uint64_t> where_;  ///< per drone: its cell's key
  std::vector<bool> placed_;
};

/// Every sample of every track (index = drone) in time order: one drone's samples in track
/// order, and at equal times the lower-numbered drone first.
struct Timeline {
  struct Step {
    double t;
    int drone;
    int index;  ///< in the drone's track
  };
  std::vector<const std::vector<dex::Sample>*> tracks;
  std::vector<Step> steps;
};
Timeline timeline(std::vector<const std::vector<dex::Sample>*> tracks);

/// Two drones, both airborne, coming nearer than the separation (horizontally and
/// vertically) at `t`, after having been apart (or not both seen) just before: a and b
/// (a < b) as the tracks had them then.
struct Approach {
  int a = 0, b = 0;
  double t = 0.0;
  const dex::Sample* pa = nullptr;
  const dex::Sample* pb = nullptr;
  double horizontal = 0.0, vertical = 0.0;
};

/// Every approach in the flight, ordered by (a, b, t): the moments at which
/// a pair is compared are the sample times of either drone, each drone at its last sample at
/// or before then.
std::vector<Approach> approaches(const Timeline& flight, const fleet::Separation& separation);

/// For each query (drone, t, x, y): the lowest-numbered other drone standing on the ground
/// (its last sample at or before t landed) nearer than `radius` horizontally to (x, y), or -1.
struct SpotQuery {
  int drone = 0;
  double t = 0.0, x = 0.0, y = 0.0;
};
std::vector<int> standing_near(const Timeline& flight, const std::vector<SpotQuery>& queries, double radius);

}  // namespace eamos::verify
