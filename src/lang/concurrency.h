#pragma once
// The "two motion actions of one drone may run at the same time" warning. A drone flies
// one motion at a time (a new one preempts the old), so overlapping motions are usually a
// mistake — or, like Listing 2's Orbit ended by Land, a deliberate preemption worth
// seeing in the compiler output.
#include <vector>

#include "diag/diagnostics.h"
#include "fleet/catalog.h"
#include "lang/ast.h"

namespace eamos::lang {

/// Statements run concurrently when they are siblings in a PAR block, or when one is
/// launched by async(...) / Do*Async and the other follows it in the same sequence.
/// Branches of one control structure never overlap (If picks one; Repeat and Do*Sync
/// run theirs one after the other).
void warn_concurrent_motion(const Mission& mission, const std::vector<fleet::DroneType>& types,
                            Diagnostics& diags);

}  // namespace eamos::lang
