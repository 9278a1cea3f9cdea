#include "lang/literal_arguments.h"

#include <optional>
#include <string>

#include "diag/number.h"

namespace eamos::lang {
namespace {

void check(const Mission& m, const Statement& s, Diagnostics& diags) {
  if (s.kind != StatementKind::action || s.drone_index < 0 || s.args.size() != 1) return;
  bool orbit = s.callee == "Orbit", hover = s.callee == "Hover";
  if (!orbit && !hover) return;
  std::optional<double> value = literal_number(s.args[0]);
  if (!value || (orbit && *value > 0) || (hover && *value >= 0)) return;
  std::string call = std::string(s.drone) + "." + std::string(s.callee) + ": ";
  std::string v = diag::number_text(*value);
  if (orbit)
    diags.error(m.file, s.args[0]->loc, call + "orbit radius " + v + " m is not above 0, and the drone refuses it; " +
                                            "give the radius in metres, or write Orbit() for the default radius");
  else
    diags.error(m.file, s.args[0]->loc, call + "hover duration " + v + " s is negative, and the drone refuses it; " +
                                            "give the seconds to hold, or write Hover() to hold until a later motion");
}

}  // namespace

void check_literal_arguments(const Mission& mission, Diagnostics& diags) {
  for (const Function& f : mission.functions)
    for (const Statement& s : f.body) check(mission, s, diags);
}

}  // namespace eamos::lang
