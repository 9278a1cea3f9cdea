#pragma once
// Static checks of a parsed mission against the platform catalog. It resolves names in
// place (drone and function indices, control-structure kinds, expression types) so that
// the graph builders can trust the AST, and reports every problem it finds in one pass.
#include <vector>

#include "diag/diagnostics.h"
#include "fleet/fleet.h"
#include "lang/ast.h"

namespace eamos::lang {

/// The longest drone name: the common name of its DDS Security certificate (X.509: 64).
inline constexpr std::size_t kMaxDroneNameLength = 64;

/// Upper bounds that keep any input from exhausting time or memory: calls are expanded
/// into the AMT (each call instantiates its block), so a small file can ask for a huge tree.
struct CheckLimits {
  long long max_expanded_nodes = 20'000'000;
  int max_call_depth = 1000;
};

struct CheckedMission {
  std::vector<fleet::DroneType> drone_types;  ///< per declared drone, in declaration order
  long long expanded_statements = 0;          ///< AMT size estimate (statements after expansion)
};

/// Checks `mission`; errors and warnings go to `diags`. The result is meaningful only
/// when no error was reported.
CheckedMission check_mission(Mission& mission, const fleet::Fleet& fleet, Diagnostics& diags,
                             const CheckLimits& limits = {});

/// True for names the language reserves for blocks.
bool is_block_name(std::string_view name);

/// A control structure's signature as docs/language.md §8 writes it, e.g.
/// "If(condition, SEQ_then, SEQ_else)"; "" for ControlKind::none.
const char* control_usage(ControlKind kind);
/// What it does, in one sentence (docs/language.md §8 has the whole story); "" for none.
const char* control_meaning(ControlKind kind);

}  // namespace eamos::lang
