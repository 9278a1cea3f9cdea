#pragma once
// The "literal argument the drone refuses" rule for the actions whose arguments have a range
// of their own: an Orbit written with a radius that is not positive, a Hover with a negative
// duration. The drone refuses them at run time (mid::uniform_refusal); `eamos check` reports
// them at the argument instead. Altitudes are src/lang/altitude.h's.
#include "diag/diagnostics.h"
#include "lang/ast.h"

namespace eamos::lang {

/// An error at each Orbit(r) whose literal r is not above 0 and each Hover(t) whose literal t
/// is below 0. A computed argument is the drone's to refuse in flight.
void check_literal_arguments(const Mission& mission, Diagnostics& diags);

}  // namespace eamos::lang
