#include "lang/exact_compare.h"

#include <string>
#include <utility>

#include "diag/number.h"

namespace eamos::lang {

using diag::number_text;
namespace {

bool reads_property(const Expr& e) {
  if (e.kind == ExprKind::property) return true;
  return (e.lhs && reads_property(*e.lhs)) || (e.rhs && reads_property(*e.rhs));
}

// The bounds of a ±0.5 band around the right side: folded when it is a literal.
std::pair<std::string, std::string> band(const Expr& rhs) {
  if (rhs.kind == ExprKind::number) return {number_text(rhs.number - 0.5), number_text(rhs.number + 0.5)};
  std::string r = expr_text(rhs);
  return {r + " - 0.5", r + " + 0.5"};
}

std::string tolerance_hint(const Expr& e) {
  std::string l = expr_text(*e.lhs);
  auto [low, high] = band(*e.rhs);
  if (e.op == Op::eq)
    return "is almost never true on a real vehicle; write a tolerance, e.g. '" + l + " >= " + low +
           " && " + l + " <= " + high + "', or a one-sided '>=' / '<='";
  return "is almost always true on a real vehicle; write a tolerance, e.g. '" + l + " < " + low +
         " || " + l + " > " + high + "'";
}

void visit(const Expr& e, const Mission& m, Diagnostics& diags) {
  if ((e.op == Op::eq || e.op == Op::ne) && e.kind == ExprKind::binary && e.lhs && e.rhs &&
      e.lhs->type == ValueType::number && (reads_property(*e.lhs) || reads_property(*e.rhs)))
    diags.warning(m.file, e.loc,
                  "'" + expr_text(e) + "' compares a measured value exactly: positions, battery " +
                      "and sensor readings of a real vehicle are estimates, never exact as in the " +
                      "simulator, so it " + tolerance_hint(e));
  if (e.lhs) visit(*e.lhs, m, diags);
  if (e.rhs) visit(*e.rhs, m, diags);
}

}  // namespace

void warn_exact_comparisons(const Mission& mission, Diagnostics& diags) {
  for (const Function& f : mission.functions)
    for (const Statement& s : f.body)
      for (const auto& arg : s.args)
        if (arg) visit(*arg, mission, diags);
}

}  // namespace eamos::lang
