#pragma once
#include <string>

namespace eamos::diag {

// A number as a message shows it to its reader: printf's %g (at most six significant digits,
// no trailing zeros: 5, 0.25, 1e+06), the one form every library's errors and notes use.
std::string number_text(double v);

}  // namespace eamos::diag
