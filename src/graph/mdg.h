#pragma once
// Mission Dependency Graphs (paper, section IV.C): one per drone, holding the drone's own
// (internal) nodes and the other drones' (external) nodes it exchanges triggers or
// control messages with. Sync points (init, forks) are cloned onto every drone they start,
// so that every drone waits on its own copy; conditions stay with the one drone that
// evaluates them and appear as external nodes to the drones that follow their outcome; the
// mission end node is held by the first declared drone (the mission lead).
//
// A sync point is a barrier, and it costs O(k) for k drones, not O(k²): a drone whose
// work leads into it counts its own arcs, then announces its arrival once to every clone
// holder (`notify`); each clone counts the arrivals it needs (`waits`). Both name a set of
// drones in the MDG's table `drone_sets`, shared by every sync point with the same set.
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "graph/meg.h"

namespace eamos::graph {

struct MdgNode {
  int meg = 0;            ///< the MEG node this is (a clone, for sync points)
  int drone = 0;          ///< the drone that holds it: owner, or clone holder
  bool internal = false;  ///< true when `drone` is the MDG's drone
  /// Internal sync-point clones: the drones whose arrival it waits for (an index into
  /// Mdg::drone_sets; -1 none). The set may hold this drone, whose arrival is its own arcs.
  int waits = -1;
  /// Sync points this drone's work leads into: the drones holding a clone, told once when
  /// all of this MDG's arcs into the node have fired (index into Mdg::drone_sets; -1
  /// none). On a drone without a clone of its own the node is external (a copy of the
  /// first holder's clone) and only counts and announces.
  int notify = -1;
  /// Do conditions: the nodes of this MDG it cancels (an index into Mdg::cancel_lists; -1
  /// none). Kept out of the node, which a large mission has a million of.
  int cancels = -1;
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
  std::vector<std::vector<int>> drone_sets;  ///< sorted drone lists named by `waits` and `notify`
  std::vector<std::vector<int>> cancel_lists;  ///< indices into `nodes`, named by MdgNode::cancels

  /// The nodes that node `node` cancels (empty for all but Do conditions).
  std::span<const int> cancels(int node) const;
  /// Node `node`'s list of cancelled nodes, made when first asked for (as Meg::lists_of).
  std::vector<int>& cancel_list(int node);

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

/// The drones whose work leads into each sync point (empty for other nodes): the holders
/// of its non-sync predecessors, sorted.
std::vector<std::vector<int>> sync_arrivers(const Meg& meg);

/// A sorted drone set as [first, last] runs of consecutive indices, the way mission files
/// and the graph export write `drone_sets`: a fleet-wide set is one run.
std::vector<std::pair<int, int>> drone_ranges(const std::vector<int>& set);

/// One MDG per drone, in declaration order.
std::vector<Mdg> build_mdgs(const Meg& meg);

}  // namespace eamos::graph
