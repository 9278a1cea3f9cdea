#pragma once
// The words the compiler and the DEX share to describe a mission graph: the 13 control
// structures, the MEG's node kinds, arc kinds and branch labels, and their spellings in
// mission files and traces. Header-only and below every other component, so the drone-side
// DEX reads a compiled graph without linking the compiler's front end. Each name stays in
// the namespace of the stage that introduces it (lang::ControlKind, graph::MegKind), which
// is how every component already spells it.
#include <string_view>

namespace eamos::lang {

/// The 13 mission control structures of the paper, rules (9)–(19).
enum class ControlKind {
  none,
  If, WaitUntil, WaitWhile, RepeatUntil, RepeatWhile, RepeatFor,
  PauseUntil, PauseWhile, PauseFor, DoUntilAsync, DoWhileAsync, DoUntilSync, DoWhileSync,
};

namespace detail {
struct ControlEntry {
  ControlKind kind;
  const char* name;
};
inline constexpr ControlEntry kControls[] = {
    {ControlKind::If, "If"},
    {ControlKind::WaitUntil, "WaitUntil"},
    {ControlKind::WaitWhile, "WaitWhile"},
    {ControlKind::RepeatUntil, "RepeatUntil"},
    {ControlKind::RepeatWhile, "RepeatWhile"},
    {ControlKind::RepeatFor, "RepeatFor"},
    {ControlKind::PauseUntil, "PauseUntil"},
    {ControlKind::PauseWhile, "PauseWhile"},
    {ControlKind::PauseFor, "PauseFor"},
    {ControlKind::DoUntilAsync, "DoUntilAsync"},
    {ControlKind::DoWhileAsync, "DoWhileAsync"},
    {ControlKind::DoUntilSync, "DoUntilSync"},
    {ControlKind::DoWhileSync, "DoWhileSync"},
};
}  // namespace detail

/// A loop: RepeatUntil, RepeatWhile or RepeatFor.
inline bool is_repeat(ControlKind k) {
  return k == ControlKind::RepeatUntil || k == ControlKind::RepeatWhile || k == ControlKind::RepeatFor;
}

/// The structure's name as written in a mission ("If"); "" for none.
inline const char* control_name(ControlKind kind) {
  for (const auto& e : detail::kControls)
    if (e.kind == kind) return e.name;
  return "";
}

/// The structure a name denotes; none for any other name.
inline ControlKind control_from_name(std::string_view name) {
  for (const auto& e : detail::kControls)
    if (name == e.name) return e.kind;
  return ControlKind::none;
}

}  // namespace eamos::lang

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

inline const char* meg_kind_name(MegKind k) {
  switch (k) {
    case MegKind::init: return "init";
    case MegKind::action: return "action";
    case MegKind::fork: return "fork";
    case MegKind::condition: return "condition";
    case MegKind::terminal: return "terminal";
    case MegKind::pause: return "pause";
    case MegKind::end: return "end";
  }
  return "";
}

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

inline const char* branch_name(Branch b) {
  switch (b) {
    case Branch::any: return "";
    case Branch::true_: return "true";
    case Branch::false_: return "false";
    case Branch::go: return "go";
    case Branch::repeat: return "repeat";
    case Branch::exit: return "exit";
    case Branch::do_: return "do";
    case Branch::skip: return "skip";
    case Branch::done: return "done";
    case Branch::continue_: return "continue";
  }
  return "";
}

enum class ArcKind {
  exec,     ///< execution link: the target may start once all its exec arcs fired
  back,     ///< execution link closing a Repeat loop: re-runs the condition
  partner,  ///< control link that releases a terminal: it ends without its branch having
            ///< run. Between the two terminals of a structure (the one that ends releases
            ///< the other, so the untaken branch counts as ended), and from a Do condition
            ///< to its do-terminal on the `skip` outcome
  stop,     ///< control link from a Do's do-terminal to its condition: stop watching
};

inline const char* arc_kind_name(ArcKind k) {
  switch (k) {
    case ArcKind::exec: return "exec";
    case ArcKind::back: return "back";
    case ArcKind::partner: return "partner";
    case ArcKind::stop: return "stop";
  }
  return "";
}

}  // namespace eamos::graph
