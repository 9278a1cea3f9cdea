#pragma once
// The "== on a measured value" warning. The simulator's positions, battery and sensor
// values can be exact (a drone at home has X() == 0); a real vehicle's are estimates that
// are never exactly any number, so such a condition that passes in simulation is almost
// never true (or, with !=, almost always true) in flight.
#include "diag/diagnostics.h"
#include "lang/ast.h"

namespace eamos::lang {

/// Warns at each `==` / `!=` between numbers where a side reads a drone property, with a
/// tolerance to write instead. Expects a type-checked mission (Expr::type filled).
void warn_exact_comparisons(const Mission& mission, Diagnostics& diags);

}  // namespace eamos::lang
