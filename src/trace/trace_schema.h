#pragma once
// The trace schema (docs/trace.md) as a check: what a trace file must hold, line by line.
// The test suite checks every example's trace with it; tools that read traces (the
// monitor) may check what they load with it before they trust it.
#include <istream>
#include <string>
#include <vector>

namespace eamos::trace {

struct TraceCheckOptions {
  /// Refuse event kinds this schema version does not define. Readers must not (a newer
  /// eamos may add kinds); eamos's own tests do, so a kind nobody documented fails them.
  bool strict = false;
};

/// Every way `in` breaks the trace schema, as "line N: what is wrong"; empty when none.
std::vector<std::string> check_trace(std::istream& in, const TraceCheckOptions& options = {});

}  // namespace eamos::trace
