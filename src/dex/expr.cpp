#include "dex/expr.h"

#include <algorithm>
#include <cmath>

namespace eamos::dex {

bool parse_expr(const nlohmann::json& j, const std::vector<std::string>& fleet, Expr& out,
                std::string& error) {
  if (!j.is_object()) {
    error = "expression is not an object";
    return false;
  }
  if (j.contains("num") && j["num"].is_number()) {
    out.kind = Expr::Kind::number;
    out.number = j["num"].get<double>();
    return true;
  }
  if (j.contains("bool") && j["bool"].is_boolean()) {
    out.kind = Expr::Kind::boolean;
    out.boolean = j["bool"].get<bool>();
    return true;
  }
  if (j.contains("prop") && j["prop"].is_string() && j.contains("drone") && j["drone"].is_string()) {
    out.kind = Expr::Kind::property;
    out.property = j["prop"].get<std::string>();
    auto it = std::find(fleet.begin(), fleet.end(), j["drone"].get<std::string>());
    if (it == fleet.end()) {
      error = "expression reads unknown drone '" + j["drone"].get<std::string>() + "'";
      return false;
    }
    out.drone = static_cast<int>(it - fleet.begin());
    return true;
  }
  if (j.contains("op") && j["op"].is_string() && j.contains("args") && j["args"].is_array()) {
    out.op = j["op"].get<std::string>();
    std::size_t n = j["args"].size();
    if (n != 1 && n != 2) {
      error = "operator '" + out.op + "' with " + std::to_string(n) + " operands";
      return false;
    }
    out.kind = n == 1 ? Expr::Kind::unary : Expr::Kind::binary;
    for (const auto& a : j["args"]) {
      Expr sub;
      if (!parse_expr(a, fleet, sub, error)) return false;
      out.args.push_back(std::move(sub));
    }
    static const char* known[] = {"-", "!", "+", "*", "/", "<", "<=", ">", ">=", "==", "!=", "&&", "||"};
    if (std::none_of(std::begin(known), std::end(known), [&](const char* k) { return out.op == k; })) {
      error = "unknown operator '" + out.op + "'";
      return false;
    }
    return true;
  }
  error = "unknown expression " + j.dump().substr(0, 80);
  return false;
}

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
