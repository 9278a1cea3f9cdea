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

  /// Levels an expression may nest (Expr::levels, counted from the whole argument or
  /// condition): deeper ones are rejected instead of recursing, so no input may exhaust the
  /// stack, and every expression compiled is one the mission reader accepts.
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
  void parse_body(Function& f);
  bool parse_statement(Statement& s);
  bool parse_arguments(std::span<Expr* const>& args);
  bool parse_argument_list();
  Expr* parse_expression(int min_precedence = 1);
  Expr* parse_unary();
  Expr* parse_primary();
  /// False, with the error at `at`, when `levels` more below the enclosing ones (depth_)
  /// pass kMaxExpressionDepth.
  bool within_depth(int levels, SourceLocation at);

  const SourceFile& file_;
  Diagnostics& diags_;
  Lexer lexer_;
  Token tok_;
  Token prev_;
  int depth_ = 0;  ///< expression levels enclosing the parse point (operators, parentheses)
  int paren_depth_ = 0;
  ExprArena arena_;  ///< moved into the Mission at the end
  std::vector<Statement> statements_;  ///< the body being parsed, moved into its Function
  std::vector<Expr*> arguments_;       ///< the argument list being parsed, copied into its Statement
};

}  // namespace eamos::lang
