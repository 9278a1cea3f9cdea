#pragma once
// A drone's mission file as the DEX holds it: the MDG with every node linked to its
// arcs, expressions ready to evaluate, and the drone's settings. Loaded once at start-up
// (the paper's "setup part", IV.D.1) by deploy::read_mission, which checks every index
// and enum in it; the engine relies on that and never changes it.
#include <cstdint>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "dex/expr.h"
#include "fleet/fleet.h"
#include "vocab/kinds.h"

namespace eamos::dex {

/// A read-only table that the Missions of one process may hold in common: the fleet's
/// names, its priorities, a drone set. Every drone's file carries them whole, so a fleet of
/// k drones in one process would hold each k times (at 10,000 drones, 10⁸ names); the
/// reads of one process share one (deploy::FleetTables). Read like the vector it holds.
template <typename T>
class SharedTable {
 public:
  SharedTable() = default;
  explicit SharedTable(T v) : p_(std::make_shared<const T>(std::move(v))) {}
  SharedTable(std::initializer_list<typename T::value_type> v) : SharedTable(T(v)) {}

  const T& get() const { return p_ ? *p_ : none(); }
  operator const T&() const { return get(); }
  auto begin() const { return get().begin(); }
  auto end() const { return get().end(); }
  std::size_t size() const { return get().size(); }
  bool empty() const { return get().empty(); }
  const typename T::value_type& operator[](std::size_t i) const { return get()[i]; }
  bool operator==(const SharedTable& o) const { return p_ == o.p_ || get() == o.get(); }
  /// Whether both hold the very same table (not only equal ones).
  bool same_as(const SharedTable& o) const { return p_ == o.p_; }

 private:
  static const T& none() {
    static const T empty_table;
    return empty_table;
  }
  std::shared_ptr<const T> p_;
};

struct Node {
  int meg = 0;                 ///< MEG id: the node's name across drones
  int drone = 0;               ///< holder (index into Mission::fleet)
  bool internal = false;       ///< held by this drone
  graph::MegKind kind = graph::MegKind::action;
  std::string name;            ///< capability, control structure, block or terminal name
  std::string text;            ///< human label for logs ("Drone1.Takeoff(3)")
  int line = 0;
  int col = 0;
  std::vector<Expr> args;      ///< action arguments
  Expr condition;              ///< condition nodes
  std::vector<int> condition_reads;  ///< drones the condition reads, computed once at load
  lang::ControlKind control = lang::ControlKind::none;
  long long count = 0;         ///< RepeatFor limit
  double seconds = 0.0;        ///< PauseFor
  int scope = -1;              ///< MEG id of the innermost Repeat/Do condition whose body holds it
  std::vector<int> cancels;    ///< Do conditions: local nodes a flip cancels
  int waits = -1;              ///< sync-point clones: drones whose arrival it needs (Mission::drone_sets)
  int waits_count = 0;         ///< of those, the other drones: arrivals that must come in
  int notify = -1;             ///< sync points: drones told when this drone arrives (Mission::drone_sets)
  std::vector<int> out;        ///< indices into Mission::arcs
  int exec_in = 0;             ///< number of exec arcs into this node
  int back_in = 0;             ///< number of back arcs into this node
};

struct Arc {
  int from = 0;  ///< index into Mission::nodes
  int to = 0;
  graph::ArcKind kind = graph::ArcKind::exec;
  graph::Branch branch = graph::Branch::any;
};

struct Mission {
  std::string hash;                    ///< SHA-256 of the whole compiled mission
  std::string source;                  ///< mission file path, for messages
  int self = 0;                        ///< this drone's index in `fleet`
  SharedTable<std::vector<std::string>> fleet;  ///< every drone's name, by index
  fleet::DroneSettings settings;       ///< this drone's settings
  fleet::DroneType type;               ///< its capabilities, as the compiler checked them
  std::vector<int> reads;              ///< drones whose telemetry this drone needs
  std::vector<Node> nodes;
  std::vector<Arc> arcs;
  std::vector<SharedTable<std::vector<int>>> drone_sets;  ///< sorted drone lists named by Node::waits and notify
  /// The fleet's `safety: min_separation`, which every drone keeps in flight (dex/separation.h).
  fleet::Separation separation;
  /// Each drone's `priority:` by fleet index (docs/fleet.md); empty: declaration order.
  SharedTable<std::vector<int>> priorities;

  /// Index of the node with MEG id `meg` held by `drone`, or -1.
  int find(int meg, int drone) const;
  /// The messages one pass through this drone's part of the mission sends (OutBridge): an
  /// `ended` from each of its nodes to each other drone it links to, an arrival per sync
  /// point it announces, a cancel to every other drone per Do condition it holds. A loop
  /// repeats them; it does not add to them.
  long long messages_per_pass() const;
  /// Key of (meg, drone) in `index`.
  static std::uint64_t key(int meg, int drone) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(meg)) << 32) | static_cast<std::uint32_t>(drone);
  }
  std::unordered_map<std::uint64_t, int> index;  ///< key(meg, drone) → node index
};

/// The last step of making a Mission, shared by the two ways to make one (a mission file
/// read by deploy::read_mission, and the compiled MDG in memory, deploy::compiled_missions),
/// so that both give the engine the same structure: from `nodes`, `arcs` and `drone_sets`
/// it fills each node's `out`, `exec_in`, `back_in`, `condition_reads` and `waits_count`,
/// and `index`. Every arc, `waits` and `self` must be in range. Returns the nodes whose
/// (meg, drone) an earlier node holds already, which `index` keeps for the earlier one.
std::vector<int> link_mission(Mission& m);

}  // namespace eamos::dex
