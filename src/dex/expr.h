#pragma once
// Expressions of mission files (conditions, action arguments) as the DEX evaluates them.
// The compiler already checked types, so evaluation cannot fail; a property of a drone
// whose telemetry has not arrived yet reads as NaN (comparisons with it are false).
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace eamos::dex {

struct Value {
  double number = 0.0;
  bool boolean = false;
  bool is_bool = false;
};

struct Expr {
  enum class Kind { none, number, boolean, property, unary, binary } kind = Kind::none;
  double number = 0.0;
  bool boolean = false;
  int drone = -1;        ///< property: drone index
  std::string property;  ///< property: "X", "Sensor1", …
  std::string op;        ///< unary/binary operator as written
  std::vector<Expr> args;
};

/// (drone index, property name) → value; booleans are 0/1.
using PropertyReader = std::function<double(int drone, const std::string& property)>;

Value evaluate(const Expr& e, const PropertyReader& read);
/// Drones whose properties the expression reads.
void collect_drones(const Expr& e, std::vector<int>& out);

}  // namespace eamos::dex
