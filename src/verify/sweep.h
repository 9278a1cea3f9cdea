#pragma once
// The pairwise checks of a flight (separation, occupied spots) in time linear in the samples:
// one sweep over every drone's track in time order, with the drones bucketed in a grid of
// cells at least the horizontal separation wide, so a drone is compared only with the drones
// in its cell and the eight around it (no nearer pair can be farther apart than one cell).
#include <vector>

#include "dex/runner.h"
#include "fleet/fleet.h"

namespace eamos::verify {

/// The horizontal extent of a flight's finite positions.
struct Area {
  double x0 = 0.0, y0 = 0.0, x1 = 0.0, y1 = 0.0;
};

/// Drones bucketed by horizontal position in square cells over an area, each cell a list
/// threaded through per-drone links: placing, moving and finding a drone cost no allocation
/// and no hashing. A position outside the area counts in the nearest cell at its edge (a
/// nearer pair still lies in neighbouring cells, as clamping never moves two cells apart).
class Grid {
 public:
  /// Cells at least `cell` wide over `area`; wider when the area would need more than
  /// kMaxCells of them (a drone far from the rest), which costs more comparisons, never a miss.
  Grid(double cell, const Area& area, int drones);
  /// Puts `drone` at (x, y); a drone at a position that is not finite is left out (it is near
  /// no one). Moving it again takes it out of its old cell.
  void place(int drone, double x, double y);
  void remove(int drone);
  /// Every drone in the cell of (x, y) and the eight around it (`drone` itself included when
  /// it is there), in no particular order.
  void around(double x, double y, std::vector<int>& out) const;

  static constexpr long kMaxCells = 1L << 18;

 private:
  /// The column (or row) of a position `offset` from the area's edge, clamped to the grid.
  int index(double offset, int count) const;
  double cell_;
  Area area_;
  int columns_ = 1, rows_ = 1;
  std::vector<int> first_;  ///< per cell: its first drone, -1 none
  std::vector<int> next_;   ///< per drone: the next drone in its cell, -1 none
  std::vector<int> prev_;   ///< per drone: the one before it, -1 when it is the first
  std::vector<int> where_;  ///< per drone: its cell, -1 when not placed
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
  Area area;  ///< the extent of every finite position
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
