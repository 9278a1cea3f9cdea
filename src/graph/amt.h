#pragma once
// The Abstract Mission Tree (paper, section IV.B): the static structure of a mission with
// every block call expanded in place. Parents are sequential and parallel blocks and
// control structures; leaves are drone actions and timed pauses.
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "diag/source.h"
#include "lang/ast.h"

namespace eamos::graph {

enum class AmtKind {
  init,     ///< the root: INIT's body, run in sequence
  seq,      ///< a SEQ_ block instance; children run one after another
  par,      ///< a PAR_ block instance; children start together
  async,    ///< async(F): one child (F's instance), detached from the sequence
  control,  ///< a mission control structure; children are its branches
  action,   ///< a drone action (leaf)
  pause,    ///< PauseFor(seconds) (leaf); PauseUntil/While are controls without branches
};
const char* amt_kind_name(AmtKind k);

/// What a branch of a control structure is for.
enum class Role { none, then_, else_, wait, repeat, after, do_, done };
const char* role_name(Role r);
/// The roles of a control structure's branches, in the order of its block arguments.
std::span<const Role> branch_roles(lang::ControlKind k);

struct AmtNode {
  // Ordered so that no field pads another: a large mission has a million nodes.
  int id = 0;
  AmtKind kind = AmtKind::seq;
  SourceLocation loc;      ///< the call site (or INIT's definition)
  int parent = -1;
  Role role = Role::none;  ///< this node's role under a control parent
  int drone = -1;          ///< action
  lang::ControlKind control = lang::ControlKind::none;  ///< control
  /// Block name, capability, or control structure name: a view into the Mission (or a
  /// literal), which outlives its AMT.
  std::string_view name;
  std::vector<int> children;
  // action:
  std::vector<const lang::Expr*> args;
  // control:
  const lang::Expr* condition = nullptr;
  long long count = 0;     ///< RepeatFor
  double seconds = 0.0;    ///< PauseFor
};

struct Amt {
  std::vector<AmtNode> nodes;  ///< nodes[0] is the root (init)
  int root() const { return 0; }
};

/// Expands INIT of a checked mission (no errors) into the AMT.
Amt build_amt(const lang::Mission& mission);

}  // namespace eamos::graph
