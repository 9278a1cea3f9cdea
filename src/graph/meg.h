#pragma once
// The Mission Execution Graph (paper, section IV.B): the dynamic execution order. A node
// runs once all of its predecessors over execution arcs have ended, then triggers its
// successors; control structures are nodes that choose which successors to trigger
// (Taskflow's condition tasks), loops are back arcs, and every branch ends in a terminal.
#include <span>
#include <string>
#include <vector>

#include "diag/source.h"
#include "graph/amt.h"
#include "lang/ast.h"
#include "vocab/kinds.h"  // MegKind, Branch, ArcKind

namespace eamos::graph {

struct MegArc {
  int from = 0;
  int to = 0;
  ArcKind kind = ArcKind::exec;
  Branch branch = Branch::any;
};

struct MegNode {
  int id = 0;
  MegKind kind = MegKind::action;
  SourceLocation loc;
  int drone = -1;          ///< owner; -1 for sync points
  /// Condition: its terminals and the nodes it cancels (an index into Meg::condition_lists;
  /// -1 none). Kept out of the node, which a large mission has a million of.
  int lists = -1;
  std::string name;        ///< capability, control structure or block name
  // action:
  std::vector<const lang::Expr*> args;
  // condition:
  lang::ControlKind control = lang::ControlKind::none;
  /// The innermost Repeat or Do condition whose body (repeat branch with its terminal, or
  /// do-branch) holds this node, -1 for none. The DEX numbers each run of a body (an epoch)
  /// so that a trigger left over from an earlier, cancelled or finished run is ignored.
  /// (Here, beside `control`, it fills what would be padding.)
  int scope = -1;
  const lang::Expr* condition = nullptr;
  std::vector<int> reads;  ///< drones whose properties the condition/arguments read
  long long count = 0;     ///< RepeatFor's iteration limit
  // terminal:
  int owner_condition = -1;    ///< the condition whose branch it ends (-1: async branch end)
  Role role = Role::none;      ///< which branch it ends
  // pause:
  double seconds = 0.0;
};

struct ConditionLists {
  std::vector<int> terminals;  ///< its terminals (then/else, repeat/after, do/done)
  std::vector<int> cancels;    ///< Do* condition: nodes of the do-branch, cancelled on a flip
};

struct Meg {
  std::vector<MegNode> nodes;
  std::vector<MegArc> arcs;
  std::vector<ConditionLists> condition_lists;  ///< named by MegNode::lists
  int init = -1;
  int end = -1;
  int drone_count = 0;

  int add_node(MegKind kind, SourceLocation loc);
  int add_arc(int from, int to, ArcKind kind = ArcKind::exec, Branch branch = Branch::any);
  /// A condition's lists, made when first asked for.
  ConditionLists& lists_of(int condition);
  std::span<const int> terminals(int node) const;
  std::span<const int> cancels(int node) const;

  /// The arcs out of and into `node` (indices into `arcs`, in the order they were added),
  /// once index_arcs() has run; build_meg runs it.
  std::span<const int> out(int node) const { return arcs_of(out_start, out_arcs, node); }
  std::span<const int> in(int node) const { return arcs_of(in_start, in_arcs, node); }
  /// Lists every node's arcs in two flat arrays: a list per node was two allocations per
  /// node, a sixth of a large MEG's memory.
  void index_arcs();

  std::vector<int> out_start, out_arcs;  ///< node n's arcs out: out_arcs[out_start[n], out_start[n + 1])
  std::vector<int> in_start, in_arcs;

 private:
  static std::span<const int> arcs_of(const std::vector<int>& start, const std::vector<int>& list, int node) {
    return {list.data() + start[node], static_cast<std::size_t>(start[node + 1] - start[node])};
  }
};

/// Builds the MEG of a checked mission (no errors), expanding INIT as build_amt does but
/// without holding an AMT. Conditions, terminals and pauses are assigned to the drone that
/// evaluates them (see docs/architecture.md: "who evaluates a condition").
Meg build_meg(const lang::Mission& mission);

}  // namespace eamos::graph
