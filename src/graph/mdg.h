#pragma once
// Mission Dependency Graphs (paper, section IV.C): one per drone, holding the drone's own
// (internal) nodes and the other drones' (external) nodes it exchanges triggers or
// control messages with. Sync points (init, forks, end) are cloned per drone so that
// every drone waits on its own copy; conditions stay with the one drone that evaluates
// them and appear as external nodes to the drones that follow their outcome; the mission
// end node is held by the first declared drone (the mission lead).
#include <cstdint>
#include <vector>

#include "graph/meg.h"

namespace eamos::graph {

struct MdgNode {
  int meg = 0;            ///< the MEG node this is (a clone, for sync points)
  int drone = 0;          ///< the drone that holds it: owner, or clone holder
  bool internal = false;  ///< true when `drone` is the MDG's drone
  std::vector<int> cancels;  ///< Do conditions: indices of this MDG's nodes it cancels
};

struct MdgArc {
  int from = 0;  ///< index into Mdg::nodes
  int to = 0;
  ArcKind kind = ArcKind::exec;
  Branch branch = Branch::any;
};

struct Mdg {
  int drone = 0;
  std::vector<MdgNode> nodes;
  std::vector<MdgArc> arcs;
  std::vector<int> reads;  ///< drones whose telemetry this drone's conditions and arguments need

  int find(int meg, int drone) const;  ///< index of the node, or -1
  bool external(const MdgArc& a) const { return !nodes[a.from].internal || !nodes[a.to].internal; }
  std::size_t internal_count() const;
};

/// A node instance of the whole distributed mission: (MEG node, drone holding it).
struct Instance {
  int meg = 0;
  int drone = 0;
};

/// The drones holding a clone of each sync point (empty for other nodes): the drones of
/// the first non-sync nodes reached forward through sync points.
std::vector<std::vector<int>> sync_clones(const Meg& meg);

/// One MDG per drone, in declaration order.
std::vector<Mdg> build_mdgs(const Meg& meg);

}  // namespace eamos::graph
