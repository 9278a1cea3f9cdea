#pragma once
// Recursive-descent parser for the mission language: one function per grammar rule,
// named after it, the rule in a comment above it (docs/language.md has the whole grammar).
// On a syntax error it reports, skips to the next statement or declaration, and goes on.
#include "diag/diagnostics.h"
#include "lang/ast.h"
#include "lang/lexer.h"

namespace eamos::lang {

/// Parses `file` into `mission`; syntax errors go to `diags`. Always returns a Mission
/// (possibly partial) so that later checks can still report what they find.
Mission parse_mission(const SourceFile& file, Diagnostics& diags);

class Parser {
 public:
  Parser(const SourceFile& file, Diagnostics& diags);
  Mission parse();

  /// Deeper expressions are rejected instead of recursing: no input may exhaust the stack.
  static constexpr int kMaxExpressionDepth = 200;

 private:
  void advance();
  bool accept(TokenKind kind);
  bool expect(TokenKind kind, const char* what);
  void error_here(const std::string& message);
  void skip_to_statement_end();
  void skip_to_declaration();
  void skip_implicit_semicolons();

  void parse_package(Mission& m);
  void parse_drone(Mission& m);
  void parse_function(Mission& m);
  void parse_block(Function& f);
  bool parse_statement(Statement& s);
  bool parse_arguments(std::vector<std::unique_ptr<Expr>>& args);
  std::unique_ptr<Expr> parse_expression(int min_precedence = 1);
  std::unique_ptr<Expr> parse_unary();
  std::unique_ptr<Expr> parse_primary();

  const SourceFile& file_;
  Diagnostics& diags_;
  Lexer lexer_;
  Token tok_;
  Token prev_;
  int depth_ = 0;
  int paren_depth_ = 0;
};

}  // namespace eamos::lang
