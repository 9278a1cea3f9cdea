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

namespace eamos::graph {

enum class MegKind {
  init,       ///< mission start; a sync point cloned onto every drone that needs it
  action,     ///< a drone action
  fork,       ///< start of a PAR block; a sync point (no drone until the MDG clones it)
  condition,  ///< a control structure's decision; evaluated by exactly one drone
  terminal,   ///< end of a control-structure branch (or of an async branch)
  pause,      ///< PauseFor: a timer on one drone
  end,        ///< mission end: held by the mission lead (the first declared drone)
};
const char* meg_kind_name(MegKind k);
/// Sync points have no drone of their own; the MDG clones them per drone.
inline bool is_sync_point(MegKind k) { return k == MegKind::init || k == MegKind::fork; }

/// Which outcome of a condition an arc follows; `any` for every other source node.
enum class Branch {
  any,
  true_,     ///< If: condition held
  false_,    ///< If: condition did not hold
  go,        ///< Wait*/Pause*: the awaited state was reached
  repeat,    ///< Repeat*: run one more iteration
  exit,      ///< Repeat*: stop repeating, run the after-branch
  do_,       ///< Do*: condition says "do", start the do-branch
  skip,      ///< Do*: condition says "don't", nothing to do
  done,      ///< Do*: condition flipped while the do-branch ran; it was cancelled
  continue_, ///< Do*Async: the sequence goes on at once
};
const char* branch_name(Branch b);

enum class ArcKind {
  exec,     ///< execution link: the target may start once all its exec arcs fired
  back,     ///< execution link closing a Repeat loop: re-runs the condition
  partner,  ///< control link that releases a terminal: it ends without its branch having
            ///< run. Between the two terminals of a structure (the one that ends releases
            ///< the other, so the untaken branch counts as ended), and from a Do condition
            ///< to its do-terminal on the `skip` outcome
  stop,     ///< control link from a Do's do-terminal to its condition: stop watching
};
const char* arc_kind_name(ArcKind k);

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
  int amt = -1;            ///< the AMT node it came from (-1 for init/end)
  int drone = -1;          ///< owner; -1 for sync points
  std::string name;        ///< capability, control structure or block name
  std::vector<int> out;    ///< indices into Meg::arcs
  std::vector<int> in;
  // action:
  std::vector<const lang::Expr*> args;
  // condition:
  lang::ControlKind control = lang::ControlKind::none;
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
  /// The innermost Repeat or Do condition whose body (repeat branch with its terminal, or
  /// do-branch) holds this node, -1 for none. The DEX numbers each run of a body (an epoch)
  /// so that a trigger left over from an earlier, cancelled or finished run is ignored.
  int scope = -1;
};

struct Meg {
  std::vector<MegNode> nodes;
  std::vector<MegArc> arcs;
  int init = -1;
  int end = -1;
  int drone_count = 0;

  int add_node(MegKind kind, SourceLocation loc, int amt = -1);
  int add_arc(int from, int to, ArcKind kind = ArcKind::exec, Branch branch = Branch::any);
};

/// Builds the MEG from the AMT. Conditions, terminals and pauses are assigned to the drone
/// that evaluates them (see docs/architecture.md: "who evaluates a condition").
Meg build_meg(const Amt& amt, const lang::Mission& mission);

}  // namespace eamos::graph
