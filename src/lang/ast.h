#pragma once
// The abstract syntax tree of one mission file, as parsed, plus the names the checker
// resolves into it (drone indices, function indices, control-structure kinds). Plain
// structs owned by a Mission; later stages point into it and never copy expressions.
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "diag/source.h"
#include "vocab/kinds.h"  // ControlKind

namespace eamos::lang {

enum class ExprKind : unsigned char {
  number,    ///< 3, 4.5
  boolean,   ///< true, false
  property,  ///< Drone1.X() — a property read of a declared drone
  name,      ///< a bare identifier: a block name inside a control structure's arguments
  unary,     ///< -e, !e
  binary,    ///< e op e
};

enum class Op : unsigned char { none, neg, not_, add, sub, mul, div, lt, le, gt, ge, eq, ne, and_, or_ };
const char* op_text(Op op);

enum class ValueType : unsigned char { unknown, number, boolean };

struct Expr {
  ExprKind kind = ExprKind::number;
  Op op = Op::none;
  ValueType type = ValueType::unknown;  ///< filled by the checker
  bool integer_literal = false;  ///< written without '.' or exponent
  bool boolean = false;
  /// How deep it nests: 1 for a value, one more for each operator and each pair of
  /// parentheses on its deepest path (the parser's limit, Parser::kMaxExpressionDepth).
  short levels = 1;
  int drone_index = -1;  ///< property: index into Mission::drones, filled by the checker
  SourceLocation loc;
  double number = 0.0;
  // Views into the mission's SourceFile, which outlives the Mission: a large mission holds
  // over a million expressions, and a copy of each name would be a third of their memory.
  std::string_view drone;     ///< property: the drone; name: the identifier
  std::string_view property;  ///< property: the property name
  Expr* lhs = nullptr;  ///< unary operand or left operand; owned by Mission::expressions
  Expr* rhs = nullptr;
};

/// Owns a mission's expressions in chunks: one allocation per few thousand instead of one
/// each (a million separate allocations cost their headers and scatter a tree over the heap).
/// Addresses stay valid as it grows and when it is moved. A chunk is raw memory, each
/// expression constructed as it is made: the unused end of the last chunk is never touched,
/// so it costs no page faults.
class ExprArena {
 public:
  Expr* make();
  std::size_t size() const { return size_; }
  /// A copy of `list` that lives as long as the arena: a statement's arguments, kept in chunks
  /// as the expressions are rather than in an allocation of their own each.
  std::span<Expr* const> keep(std::span<Expr* const> list);

 private:
  static_assert(std::is_trivially_destructible_v<Expr>, "a chunk is freed without destroying its expressions");
  static constexpr std::size_t kChunk = 4096;
  static constexpr std::size_t kListChunk = 8192;  ///< argument pointers per chunk
  std::vector<std::unique_ptr<std::byte[]>> chunks_;
  std::size_t used_ = kChunk;  ///< in the last chunk
  std::size_t size_ = 0;
  std::vector<std::unique_ptr<Expr*[]>> lists_;  ///< the last one is filled from lists_used_ on
  std::size_t lists_used_ = kListChunk;
  std::vector<std::unique_ptr<Expr*[]>> long_lists_;
};

enum class StatementKind {
  action,     ///< Drone.Capability(args)
  call,       ///< SEQ_x() / PAR_x(), or a control structure If(...) once resolved
  async_call, ///< async(SEQ_x)
};

struct Statement {
  // Ordered so that no field pads another: a large mission has a million statements.
  StatementKind kind = StatementKind::action;
  // Filled by the checker:
  int drone_index = -1;                      ///< action
  int function_index = -1;                   ///< call / async_call of a block
  ControlKind control = ControlKind::none;   ///< call of a control structure
  SourceLocation loc;         ///< first token
  SourceLocation callee_loc;  ///< the capability or function name
  std::string_view drone;     ///< action only; a view into the SourceFile, as Expr's names
  std::string_view callee;    ///< capability name, or block / control structure name
  std::span<Expr* const> args;  ///< the list and its expressions owned by Mission::expressions
  std::vector<int> branch_functions;         ///< control, filled by the checker: functions named in the args, in order
};

enum class BlockKind { seq, par };

struct Function {
  std::string name;
  std::vector<Statement> body;
  SourceLocation loc;  ///< the name after `func`
  BlockKind block = BlockKind::seq;  ///< INIT and SEQ_* run in sequence, PAR_* in parallel
  bool called = false;  ///< filled by the checker
};

struct DroneDecl {
  std::string name;
  std::string type;
  SourceLocation loc;
  SourceLocation type_loc;
};

struct Mission {
  const SourceFile* file = nullptr;
  std::string package;
  std::vector<DroneDecl> drones;
  std::vector<Function> functions;
  ExprArena expressions;  ///< every expression of the statements, which point into it
  int init_function = -1;  ///< index of INIT, filled by the checker

  int find_drone(const std::string& name) const;
  int find_function(const std::string& name) const;
};

/// Source text of an expression, normalised ("Drone1.X() >= 5"), for labels and logs.
std::string expr_text(const Expr& e);
/// expr_text appended to `out`: a writer labelling every node reuses one string.
void append_expr_text(std::string& out, const Expr& e);
/// The value of a number written out (`5`, `-3.5`), for the rules that check what a drone
/// would refuse; nothing for anything computed (or null).
std::optional<double> literal_number(const Expr* e);

}  // namespace eamos::lang
