#include "lang/loop_time.h"

#include <string>
#include <vector>

namespace eamos::lang {
namespace {

/// 1 for the literal `true`, 0 for `false`, -1 for anything else (decided at run time).
int literal_truth(const Expr* e) {
  if (!e || e->kind != ExprKind::boolean) return -1;
  return e->boolean ? 1 : 0;
}

// Whether a statement or block is certain to wait for something (an action's end, a
// timer, a condition) before it ends. "Certain" is taken over every path: a branch that
// may be skipped or that continues at once gives no such certainty.
class LoopTime {
 public:
  explicit LoopTime(const Mission& m) : m_(m), state_(m.functions.size(), State::unknown) {}

  bool block_waits(int f) {
    // Unresolved names and recursion are other checks' errors; count them as waiting so
    // this rule adds no second error for them.
    if (f < 0 || f >= static_cast<int>(m_.functions.size())) return true;
    if (state_[f] == State::visiting) return true;
    if (state_[f] != State::unknown) return state_[f] == State::waits;
    state_[f] = State::visiting;
    bool waits = false;
    for (const Statement& s : m_.functions[f].body) waits = statement_waits(s) || waits;
    state_[f] = waits ? State::waits : State::instant;
    return waits;
  }

  bool statement_waits(const Statement& s) {
    switch (s.kind) {
      case StatementKind::action: return true;
      case StatementKind::async_call: return false;
      case StatementKind::call:
        return s.control == ControlKind::none ? block_waits(s.function_index) : control_waits(s);
    }
    return true;
  }

  /// Why block f can end without waiting, for the error message.
  std::string why_instant(int f) {
    const Function& fn = m_.functions[f];
    if (fn.body.empty()) return "'" + fn.name + "' is empty";
    std::string out;
    int shown = 0;
    for (const Statement& s : fn.body) {
      if (shown == 3) {
        out += "; …";
        break;
      }
      out += (shown++ ? "; " : "") + why_statement(s);
    }
    return "in '" + fn.name + "', " + out;
  }

 private:
  enum class State { unknown, visiting, waits, instant };

  int branch(const Statement& s, std::size_t i) const {
    return i < s.branch_functions.size() ? s.branch_functions[i] : -1;
  }
  const Expr* condition(const Statement& s) const { return s.args.empty() ? nullptr : s.args[0]; }

  bool control_waits(const Statement& s) {
    int c = literal_truth(condition(s));
    switch (s.control) {
      case ControlKind::If:
        if (c == 1) return block_waits(branch(s, 0));
        if (c == 0) return block_waits(branch(s, 1));
        return block_waits(branch(s, 0)) && block_waits(branch(s, 1));
      case ControlKind::WaitUntil: return c == 1 ? block_waits(branch(s, 0)) : true;
      case ControlKind::WaitWhile: return c == 0 ? block_waits(branch(s, 0)) : true;
      case ControlKind::PauseUntil: return c != 1;
      case ControlKind::PauseWhile: return c != 0;
      case ControlKind::PauseFor:
        return s.args.empty() || s.args[0]->kind != ExprKind::number || s.args[0]->number > 0;
      case ControlKind::RepeatUntil:
      case ControlKind::RepeatWhile:
      case ControlKind::RepeatFor: {
        // The after-branch always runs; the repeat branch only if the first test is decided.
        bool first_iteration_certain = s.control == ControlKind::RepeatUntil ? c == 0 : c == 1;
        return block_waits(branch(s, 1)) || (first_iteration_certain && block_waits(branch(s, 0)));
      }
      case ControlKind::DoUntilSync:
      case ControlKind::DoWhileSync: {
        // A constant "do" never flips, so the do-branch runs to its end; otherwise both
        // branches may be skipped.
        int do_value = s.control == ControlKind::DoWhileSync ? 1 : 0;
        return c == do_value && block_waits(branch(s, 0));
      }
      case ControlKind::DoUntilAsync:
      case ControlKind::DoWhileAsync:
      case ControlKind::none: return false;
    }
    return true;
  }

  std::string name_of(int f) const {
    return f >= 0 && f < static_cast<int>(m_.functions.size()) ? m_.functions[f].name : "?";
  }

  std::string why_statement(const Statement& s) {
    std::string line = " (line " + std::to_string(s.loc.line) + ")";
    if (s.kind == StatementKind::async_call)
      return "async(" + name_of(s.function_index) + ")" + line + " continues at once";
    if (s.kind == StatementKind::action) return std::string(s.drone) + "." + std::string(s.callee) + line + " waits";
    if (s.control == ControlKind::none) {
      if (block_waits(s.function_index)) return std::string(s.callee) + "()" + line + " waits";
      bool empty = m_.functions[s.function_index].body.empty();
      return std::string(s.callee) + "()" + line + (empty ? " is empty" : " does not wait either");
    }
    std::string name = control_name(s.control);
    if (control_waits(s)) return name + line + " waits";
    switch (s.control) {
      case ControlKind::If: return name + line + " may take a branch that does not wait";
      case ControlKind::PauseFor: return "PauseFor(0)" + line + " takes no time";
      case ControlKind::WaitUntil:
      case ControlKind::WaitWhile:
      case ControlKind::PauseUntil:
      case ControlKind::PauseWhile: return name + line + " has a condition that is met at once";
      case ControlKind::RepeatUntil:
      case ControlKind::RepeatWhile:
      case ControlKind::RepeatFor:
        return name + line + " may run no iteration, and '" + name_of(branch(s, 1)) + "' does not wait";
      case ControlKind::DoUntilSync:
      case ControlKind::DoWhileSync: return name + line + " runs no branch when its condition says not to do";
      default: return name + line + " continues at once";
    }
  }

  const Mission& m_;
  std::vector<State> state_;
};

}  // namespace

namespace {
/// A RepeatFor whose literal count stays below the DEX's guard: it cannot hang.
bool bounded_below_guard(const Statement& s) {
  if (s.control != ControlKind::RepeatFor || s.args.size() < 4 || !s.args[3]) return false;
  const Expr& n = *s.args[3];
  return n.kind == ExprKind::number && n.number >= 0 && n.number < static_cast<double>(kMaxInstantIterations);
}
}  // namespace

void check_loops_take_time(const Mission& mission, Diagnostics& diags) {
  LoopTime loops(mission);
  for (const Function& f : mission.functions)
    for (const Statement& s : f.body) {
      if (s.kind != StatementKind::call || !is_repeat(s.control) || s.branch_functions.empty()) continue;
      int body = s.branch_functions[0];
      if (body < 0 || loops.block_waits(body)) continue;
      std::string why = std::string(control_name(s.control)) + " can repeat without mission time passing: " +
                        loops.why_instant(body) + ", so an iteration can end at the instant it began; ";
      std::string fix = "add an action or a PauseFor(seconds) to '" + mission.functions[body].name +
                        "', or wait with PauseUntil/PauseWhile instead of looping";
      if (bounded_below_guard(s)) {
        diags.warning(mission.file, s.loc,
                      why + "it ends after its count (below the " + std::to_string(kMaxInstantIterations) +
                          " instant iterations the DEX allows), but its iterations may all fall in one instant; " +
                          fix);
        continue;
      }
      diags.error(mission.file, s.loc, why + fix);
    }
}

}  // namespace eamos::lang
