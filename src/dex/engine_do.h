#pragma once
// The Do family (DoUntilSync, DoWhileSync, DoUntilAsync, DoWhileAsync) as the engine runs
// it: which control kinds are Dos and what their condition's value means. The engine's Do
// state (one watched run of the do-branch per condition, its flip and the cancel of that
// run on every drone) lives in engine_do.cpp, behind Engine::activate_do,
// Engine::recheck_do and Engine::cancel_do_run.
#include "vocab/kinds.h"

namespace eamos::dex {

inline bool is_do(lang::ControlKind k) {
  return k == lang::ControlKind::DoUntilSync || k == lang::ControlKind::DoWhileSync ||
         k == lang::ControlKind::DoUntilAsync || k == lang::ControlKind::DoWhileAsync;
}

/// Do*Async: the sequence goes on at once, beside the do-branch (MEG arc `continue`).
inline bool is_async_do(lang::ControlKind k) {
  return k == lang::ControlKind::DoUntilAsync || k == lang::ControlKind::DoWhileAsync;
}

/// Whether the Do condition's value `v` says "do" (While: true, Until: false).
inline bool says_do(lang::ControlKind k, bool v) {
  bool is_while = k == lang::ControlKind::DoWhileSync || k == lang::ControlKind::DoWhileAsync;
  return is_while ? v : !v;
}

}  // namespace eamos::dex
