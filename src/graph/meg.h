#pragma once
// The Mission Execution Graph (paper, section IV.B): the dynamic execution order. A node
// runs once all of its predecessors over execution arcs have ended, then triggers its
// successors; control structures are nodes that choose which successors to trigger
// (Taskflow's condition tasks), loops are back arcs, and every branch ends in a terminal.
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
  std::string name;        ///< capability, control structure or block name
  std::vector<int> out;    ///< indices into Meg::arcs
  std::vector<int> in;
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
  std::vector<int> terminals;  ///< condition: its terminals (then/else, repeat/after, do/done)
  std::vector<int> cancels;    ///< Do* condition: nodes of the do-branch, cancelled on a flip
  // terminal:
  int owner_condition = -1;    ///< the condition whose branch it ends (-1: async branch end)
  Role role = Role::none;      ///< which branch it ends
  // pause:
  double seconds = 0.0;
};

struct Meg {
  std::vector<MegNode> nodes;
  std::vector<MegArc> arcs;
  int init = -1;
  int end = -1;
  int drone_count = 0;

  int add_node(MegKind kind, SourceLocation loc);
  int add_arc(int from, int to, ArcKind kind = ArcKind::exec, Branch branch = Branch::any);
};

/// Builds the MEG of a checked mission (no errors), expanding INIT as build_amt does but
/// without holding an AMT. Conditions, terminals and pauses are assigned to the drone that
/// evaluates them (see docs/architecture.md: "who evaluates a condition").
Meg build_meg(const lang::Mission& mission);

}  // namespace eamos::graph
