#include "dex/expr.h"

#include <algorithm>
#include <cmath>

namespace eamos::dex {

namespace {
Value num(double v) { return {v, false, false}; }
Value boolean(bool b) { return {b ? 1.0 : 0.0, b, true}; }
}  // namespace

Value evaluate(const Expr& e, const PropertyReader& read) {
  switch (e.kind) {
    case Expr::Kind::none: return num(NAN);
    case Expr::Kind::number: return num(e.number);
    case Expr::Kind::boolean: return boolean(e.boolean);
    case Expr::Kind::property: {
      double v = read(e.drone, e.property);
      if (e.property == "Armed" || e.property == "Landed") return boolean(v != 0.0 && !std::isnan(v));
      return num(v);
    }
    case Expr::Kind::unary: {
      Value a = evaluate(e.args[0], read);
      return e.op == "!" ? boolean(!a.boolean) : num(-a.number);
    }
    case Expr::Kind::binary: {
      // && and || short-circuit like Go; the right side is not read when not needed.
      if (e.op == "&&") return boolean(evaluate(e.args[0], read).boolean && evaluate(e.args[1], read).boolean);
      if (e.op == "||") return boolean(evaluate(e.args[0], read).boolean || evaluate(e.args[1], read).boolean);
      Value a = evaluate(e.args[0], read), b = evaluate(e.args[1], read);
      if (e.op == "+") return num(a.number + b.number);
      if (e.op == "-") return num(a.number - b.number);
      if (e.op == "*") return num(a.number * b.number);
      if (e.op == "/") return num(a.number / b.number);
      if (e.op == "<") return boolean(a.number < b.number);
      if (e.op == "<=") return boolean(a.number <= b.number);
      if (e.op == ">") return boolean(a.number > b.number);
      if (e.op == ">=") return boolean(a.number >= b.number);
      if (e.op == "==") return a.is_bool ? boolean(a.boolean == b.boolean) : boolean(a.number == b.number);
      if (e.op == "!=") return a.is_bool ? boolean(a.boolean != b.boolean) : boolean(a.number != b.number);
      return num(NAN);
    }
  }
  return num(NAN);
}

void collect_drones(const Expr& e, std::vector<int>& out) {
  if (e.kind == Expr::Kind::property && std::find(out.begin(), out.end(), e.drone) == out.end())
    out.push_back(e.drone);
  for (const auto& a : e.args) collect_drones(a, out);
}

}  // namespace eamos::dex
