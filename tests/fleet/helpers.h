#pragma once
// Parses fleet text held in a test, keeping the file alive for the diagnostics.
#include <memory>
#include <string>

#include "diag/diagnostics.h"
#include "fleet/fleet.h"

namespace eamos::fleet::test {

struct Parsed {
  Fleet fleet;
  Diagnostics diags;
  bool ok = false;
};

inline Parsed parse(const std::string& text) {
  Parsed p;
  p.diags.max_errors = 0;
  p.ok = parse_fleet(std::make_shared<SourceFile>("fleet.yaml", text), p.fleet, p.diags);
  return p;
}

/// The first error, or an empty one when there is none (so a failing test prints "").
inline Diagnostic first_error(const Diagnostics& diags) {
  for (const auto& d : diags.items())
    if (d.severity == Severity::error) return d;
  return {};
}

}  // namespace eamos::fleet::test
