#pragma once
// The "every loop iteration takes mission time" rule. A repeat branch that can end without
// waiting for anything runs its next iteration at the same instant, for ever (RepeatWhile)
// or a billion times in a row (RepeatFor): timers, telemetry and the time limit starve.
#include "diag/diagnostics.h"
#include "lang/ast.h"

namespace eamos::lang {

/// Iterations in a row a Repeat may run without mission time passing before the DEX fails
/// the mission (dex::kMaxInstantIterations; a test keeps the two equal).
inline constexpr long long kMaxInstantIterations = 10000;

/// Reports each Repeat* whose repeat branch can end, on some path, without running an
/// action, a PauseFor of more than 0 s, or a wait on a condition. An error where such a loop
/// can repeat for ever (RepeatWhile, RepeatUntil) or more often in a row than the DEX allows
/// (a RepeatFor of kMaxInstantIterations or more); a warning for a RepeatFor below that,
/// which ends after its count and cannot hang. Tolerates unresolved names and recursion
/// (other checks report those), so it runs on any mission.
void check_loops_take_time(const Mission& mission, Diagnostics& diags);

}  // namespace eamos::lang
