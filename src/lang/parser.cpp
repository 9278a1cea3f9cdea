#include "lang/parser.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <string>

namespace eamos::lang {

Mission parse_mission(const SourceFile& file, Diagnostics& diags) {
  return Parser(file, diags).parse();
}

Parser::Parser(const SourceFile& file, Diagnostics& diags)
    : file_(file), diags_(diags), lexer_(file, diags) {
  advance();
}

void Parser::advance() {
  prev_ = tok_;
  tok_ = lexer_.next();
  // Inside an argument list a newline never ends the statement (the lexer cannot see
  // parentheses); Go would reject `If(c` + newline + `, A, B)`, we read it as meant.
  while (paren_depth_ > 0 && tok_.kind == TokenKind::semicolon && tok_.text == "\n")
    tok_ = lexer_.next();
}

bool Parser::accept(TokenKind kind) {
  if (tok_.kind != kind) return false;
  advance();
  return true;
}

void Parser::error_here(const std::string& message) {
  // An invalid token was already reported by the lexer; one message per problem.
  if (tok_.kind == TokenKind::invalid) return;
  diags_.error(&file_, tok_.loc, message);
}

namespace {
std::string describe(const Token& t) {
  if (t.kind == TokenKind::semicolon && t.text == "\n") return "newline";
  if (t.kind == TokenKind::end_of_file) return "end of file";
  if (t.kind == TokenKind::identifier || t.kind == TokenKind::integer ||
      t.kind == TokenKind::decimal)
    return std::string(token_kind_name(t.kind)) + " '" + std::string(t.text.substr(0, 40)) + "'";
  return token_kind_name(t.kind);
}
}  // namespace

bool Parser::expect(TokenKind kind, const char* what) {
  if (accept(kind)) return true;
  error_here(std::string("expected ") + what + ", found " + describe(tok_));
  return false;
}

void Parser::skip_to_statement_end() {
  int parens = 0;
  while (tok_.kind != TokenKind::end_of_file) {
    if (tok_.kind == TokenKind::lparen) ++parens;
    if (tok_.kind == TokenKind::rparen && parens > 0) --parens;
    if (parens == 0 && (tok_.kind == TokenKind::semicolon || tok_.kind == TokenKind::rbrace)) return;
    if (tok_.kind == TokenKind::kw_func || tok_.kind == TokenKind::kw_var) return;
    advance();
  }
}

void Parser::skip_to_declaration() {
  while (tok_.kind != TokenKind::end_of_file && tok_.kind != TokenKind::kw_func &&
         tok_.kind != TokenKind::kw_var)
    advance();
}

void Parser::skip_implicit_semicolons() {
  while (tok_.kind == TokenKind::semicolon) advance();
}

// mission = [ "package" identifier ";" ] { ( drone | function ) ";" } EOF
Mission Parser::parse() {
  Mission m;
  m.file = &file_;
  skip_implicit_semicolons();
  if (tok_.kind == TokenKind::kw_package) parse_package(m);
  while (tok_.kind != TokenKind::end_of_file) {
    if (diags_.saturated()) break;
    skip_implicit_semicolons();
    if (tok_.kind == TokenKind::end_of_file) break;
    if (tok_.kind == TokenKind::kw_var) {
      parse_drone(m);
    } else if (tok_.kind == TokenKind::kw_func) {
      parse_function(m);
    } else {
      error_here("expected 'var' or 'func' declaration, found " + describe(tok_) +
                 "; statements belong inside a func body");
      advance();
      skip_to_declaration();
    }
  }
  m.expressions = std::move(arena_);
  return m;
}

// package = "package" identifier
void Parser::parse_package(Mission& m) {
  advance();
  if (tok_.kind == TokenKind::identifier) {
    m.package = std::string(tok_.text);
    advance();
  } else {
    error_here("expected package name after 'package', found " + describe(tok_));
    return;
  }
  if (tok_.kind != TokenKind::semicolon && tok_.kind != TokenKind::end_of_file) {
    error_here("expected newline after package name, found " + describe(tok_));
    skip_to_declaration();
  }
}

// drone = "var" drone-name drone-type
void Parser::parse_drone(Mission& m) {
  advance();
  DroneDecl d;
  d.loc = tok_.loc;
  if (tok_.kind != TokenKind::identifier) {
    error_here("expected drone name after 'var', found " + describe(tok_) +
               "; write `var Drone1 DroneType`");
    skip_to_declaration();
    return;
  }
  d.name = std::string(tok_.text);
  advance();
  d.type_loc = tok_.loc;
  if (tok_.kind != TokenKind::identifier) {
    error_here("expected drone type after '" + d.name + "', found " + describe(tok_) +
               "; write `var " + d.name + " DroneType`");
    skip_to_declaration();
    return;
  }
  d.type = std::string(tok_.text);
  advance();
  m.drones.push_back(std::move(d));
  if (tok_.kind != TokenKind::semicolon && tok_.kind != TokenKind::end_of_file) {
    error_here("expected newline after drone declaration, found " + describe(tok_));
    skip_to_declaration();
  }
}

// function = "func" funcId "(" ")" block
void Parser::parse_function(Mission& m) {
  advance();
  Function f;
  f.loc = tok_.loc;
  if (tok_.kind != TokenKind::identifier) {
    error_here("expected function name after 'func', found " + describe(tok_));
    skip_to_declaration();
    return;
  }
  f.name = std::string(tok_.text);
  f.block = f.name.rfind("PAR_", 0) == 0 ? BlockKind::par : BlockKind::seq;
  advance();
  if (!expect(TokenKind::lparen, "'(' after function name") ||
      !(tok_.kind == TokenKind::rparen ||
        (error_here("blocks take no parameters; write `func " + f.name + "() {`"), false)) ||
      !expect(TokenKind::rparen, "')'")) {
    skip_to_declaration();
    m.functions.push_back(std::move(f));
    return;
  }
  if (tok_.kind == TokenKind::semicolon) {
    error_here("unexpected newline before '{'; put the opening brace on the line of `func " +
               f.name + "()`");
    skip_implicit_semicolons();
  }
  parse_block(f);
  m.functions.push_back(std::move(f));
}

// The statements are gathered in one vector the parser reuses and moved into the body at
// its size: growing each body (and each argument list) by doubling cost an allocation per
// doubling, a million of them in a large mission, and left up to half of each unused.
void Parser::parse_block(Function& f) {
  statements_.clear();
  parse_body(f);
  f.body.reserve(statements_.size());
  for (Statement& s : statements_) f.body.push_back(std::move(s));
  statements_.clear();
}

// block = "{" { statement ";" } "}"
void Parser::parse_body(Function& f) {
  if (!expect(TokenKind::lbrace, "'{' to open the function body")) {
    skip_to_declaration();
    return;
  }
  while (tok_.kind != TokenKind::rbrace && tok_.kind != TokenKind::end_of_file) {
    if (diags_.saturated()) return;
    if (accept(TokenKind::semicolon)) continue;
    if (tok_.kind == TokenKind::kw_func || tok_.kind == TokenKind::kw_var) {
      diags_.error(&file_, f.loc,
                   "function body of '" + f.name + "' is not closed; add '}' at its end");
      return;
    }
    Statement s;
    if (parse_statement(s)) statements_.push_back(std::move(s));
    if (tok_.kind != TokenKind::semicolon && tok_.kind != TokenKind::rbrace) {
      if (tok_.kind != TokenKind::end_of_file)
        error_here("expected newline or ';' after statement, found " + describe(tok_));
      skip_to_statement_end();
    }
  }
  if (tok_.kind == TokenKind::end_of_file) {
    diags_.error(&file_, f.loc,
                 "function body of '" + f.name + "' is not closed; add '}' at its end");
    return;
  }
  advance();  // '}'
}

// statement = drone-name "." capability "(" args ")"
//           | funcId "(" ")" | control-name "(" args ")"
//           | "async" "(" funcId ")"
bool Parser::parse_statement(Statement& s) {
  s.loc = tok_.loc;
  if (tok_.kind == TokenKind::kw_async) {
    s.kind = StatementKind::async_call;
    advance();
    if (!expect(TokenKind::lparen, "'(' after async")) return skip_to_statement_end(), false;
    s.callee_loc = tok_.loc;
    if (tok_.kind != TokenKind::identifier) {
      error_here("expected block name in async(...), found " + describe(tok_) +
                 "; write `async(SEQ_name)`");
      skip_to_statement_end();
      return false;
    }
    s.callee = tok_.text;
    advance();
    if (tok_.kind == TokenKind::lparen) {
      error_here("async takes the block name without '()'; write `async(" + std::string(s.callee) + ")`");
      skip_to_statement_end();
      return false;
    }
    if (!expect(TokenKind::rparen, "')' to close async(...)")) return skip_to_statement_end(), false;
    return true;
  }
  if (tok_.kind != TokenKind::identifier) {
    error_here("expected a statement (Drone.Action(...), a block call or a control structure), found " +
               describe(tok_));
    advance();
    skip_to_statement_end();
    return false;
  }
  std::string_view first = tok_.text;
  SourceLocation first_loc = tok_.loc;
  advance();
  if (accept(TokenKind::dot)) {
    s.kind = StatementKind::action;
    s.drone = first;
    s.callee_loc = tok_.loc;
    if (tok_.kind != TokenKind::identifier) {
      error_here("expected capability name after '" + std::string(first) + ".', found " + describe(tok_));
      skip_to_statement_end();
      return false;
    }
    s.callee = tok_.text;
    advance();
  } else {
    s.kind = StatementKind::call;
    s.callee = first;
    s.callee_loc = first_loc;
  }
  if (tok_.kind != TokenKind::lparen) {
    std::string call = (s.kind == StatementKind::action ? std::string(s.drone) + "." : std::string()) + std::string(s.callee) + "()";
    error_here("expected '(' after '" + std::string(s.callee) + "', found " + describe(tok_) +
               "; calls are written " + call);
    skip_to_statement_end();
    return false;
  }
  return parse_arguments(s.args);
}

// args = [ expr { "," expr } [ "," ] ]   (within parentheses)
// Returns false after a syntax error: the statement is dropped, so the checker does not
// add a follow-on "wrong number of arguments" for an argument list that was cut short.
bool Parser::parse_arguments(std::span<Expr* const>& args) {
  arguments_.clear();
  if (!parse_argument_list()) return false;
  args = arena_.keep(arguments_);
  return true;
}

bool Parser::parse_argument_list() {
  ++paren_depth_;
  advance();  // '('
  while (tok_.kind != TokenKind::rparen) {
    auto e = parse_expression();
    if (!e) {
      --paren_depth_;
      skip_to_statement_end();
      return false;
    }
    arguments_.push_back(e);
    if (tok_.kind == TokenKind::comma) {
      advance();
      continue;
    }
    if (tok_.kind != TokenKind::rparen) {
      if (tok_.kind == TokenKind::end_of_file || tok_.loc.line > prev_.loc.line)
        diags_.error(&file_, {prev_.loc.line, prev_.loc.col + static_cast<int>(prev_.text.size())},
                     "expected ')' to close the argument list, found " + describe(tok_));
      else
        error_here("expected ',' or ')' in argument list, found " + describe(tok_));
      --paren_depth_;
      skip_to_statement_end();
      return false;
    }
  }
  --paren_depth_;
  advance();  // ')'
  return true;
}

namespace {
// Go's binary operator precedence (5 binds tightest).
int binary_precedence(TokenKind k, Op& op) {
  switch (k) {
    case TokenKind::or_or: op = Op::or_; return 1;
    case TokenKind::and_and: op = Op::and_; return 2;
    case TokenKind::equal_equal: op = Op::eq; return 3;
    case TokenKind::bang_equal: op = Op::ne; return 3;
    case TokenKind::less: op = Op::lt; return 3;
    case TokenKind::less_equal: op = Op::le; return 3;
    case TokenKind::greater: op = Op::gt; return 3;
    case TokenKind::greater_equal: op = Op::ge; return 3;
    case TokenKind::plus: op = Op::add; return 4;
    case TokenKind::minus: op = Op::sub; return 4;
    case TokenKind::star: op = Op::mul; return 5;
    case TokenKind::slash: op = Op::div; return 5;
    default: op = Op::none; return 0;
  }
}

/// The value of a number token; false when it is out of range. An integer of up to 15
/// digits is exact in a double, so it is read digit by digit to the value strtod gives;
/// most literals of a large mission are such, and strtod (with a copy of the text to
/// terminate it) was a tenth of the parse.
bool read_number(const Token& t, double& value) {
  if (t.kind == TokenKind::integer && t.text.size() <= 15) {
    long long v = 0;
    for (char c : t.text) v = v * 10 + (c - '0');
    value = static_cast<double>(v);
    return true;
  }
  std::string text(t.text);
  errno = 0;
  value = std::strtod(text.c_str(), nullptr);
  return errno != ERANGE;
}

/// One level more below the current parse point while it lives.
struct DepthGuard {
  int& depth;
  explicit DepthGuard(int& d) : depth(d) { ++depth; }
  ~DepthGuard() { --depth; }
};
}  // namespace

bool Parser::within_depth(int levels, SourceLocation at) {
  // A left-leaning chain (1+1+…+1) deepens the tree without recursing, so the limit is
  // checked on the tree built, below the levels that enclose it (depth_), not only on
  // the parser's recursion: both count what the mission file will nest.
  if (depth_ + levels <= kMaxExpressionDepth) return true;
  diags_.error(&file_, at,
               "expression nested too deeply (more than " + std::to_string(kMaxExpressionDepth) +
                   " levels; each operator and each pair of parentheses is one); simplify it or split it");
  return false;
}

// expr = unary { binary-op unary }   — precedence climbing over Go's five levels
Expr* Parser::parse_expression(int min_precedence) {
  auto lhs = parse_unary();
  if (!lhs) return nullptr;
  for (;;) {
    Op op;
    int p = binary_precedence(tok_.kind, op);
    if (p == 0 || p < min_precedence) return lhs;
    SourceLocation loc = tok_.loc;
    advance();
    Expr* rhs = nullptr;
    {
      DepthGuard below(depth_);  // the operator is a level above its right operand
      rhs = parse_expression(p + 1);
    }
    if (!rhs) return nullptr;
    auto bin = arena_.make();
    bin->kind = ExprKind::binary;
    bin->loc = loc;
    bin->op = op;
    bin->levels = 1 + std::max(lhs->levels, rhs->levels);
    if (!within_depth(bin->levels, loc)) return nullptr;
    bin->lhs = lhs;
    bin->rhs = rhs;
    lhs = bin;
  }
}

// unary = ( "-" | "!" ) unary | primary
Expr* Parser::parse_unary() {
  // Every operand starts here: a value at this point is one level below depth_. Checked
  // before recursing, so no input can exhaust the stack.
  if (!within_depth(1, tok_.loc)) return nullptr;
  if (tok_.kind == TokenKind::minus || tok_.kind == TokenKind::bang) {
    auto e = arena_.make();
    e->kind = ExprKind::unary;
    e->loc = tok_.loc;
    e->op = tok_.kind == TokenKind::minus ? Op::neg : Op::not_;
    advance();
    {
      DepthGuard below(depth_);
      e->lhs = parse_unary();
    }
    if (!e->lhs) return nullptr;
    e->levels = 1 + e->lhs->levels;
    return e;
  }
  return parse_primary();
}

// primary = int | decimal | "true" | "false" | drone "." property "(" ")"
//         | identifier | "(" expr ")"
// long: one case per kind of primary expression, the grammar rule read top to bottom.
Expr* Parser::parse_primary() {
  auto e = arena_.make();
  e->loc = tok_.loc;
  switch (tok_.kind) {
    case TokenKind::integer:
    case TokenKind::decimal: {
      e->kind = ExprKind::number;
      e->integer_literal = tok_.kind == TokenKind::integer;
      if (!read_number(tok_, e->number)) {
        error_here("number '" + std::string(tok_.text.substr(0, 40)) + "' is out of range");
        return nullptr;
      }
      advance();
      return e;
    }
    case TokenKind::kw_true:
    case TokenKind::kw_false:
      e->kind = ExprKind::boolean;
      e->boolean = tok_.kind == TokenKind::kw_true;
      advance();
      return e;
    case TokenKind::lparen: {
      ++paren_depth_;
      advance();
      Expr* inner = nullptr;
      {
        DepthGuard below(depth_);  // parentheses are a level, as the limit is documented
        inner = parse_expression();
      }
      --paren_depth_;
      if (!inner) return nullptr;
      if (tok_.kind != TokenKind::rparen) {
        error_here("expected ')' to close '(', found " + describe(tok_));
        return nullptr;
      }
      advance();
      ++inner->levels;
      return inner;
    }
    case TokenKind::identifier: {
      std::string_view name = tok_.text;
      advance();
      if (tok_.kind != TokenKind::dot) {
        e->kind = ExprKind::name;
        e->drone = name;
        return e;
      }
      advance();
      if (tok_.kind != TokenKind::identifier) {
        error_here("expected property name after '" + std::string(name) + ".', found " + describe(tok_));
        return nullptr;
      }
      e->kind = ExprKind::property;
      e->drone = name;
      e->property = tok_.text;
      advance();
      if (tok_.kind != TokenKind::lparen) {
        error_here("expected '()' after property '" + std::string(name) + "." + std::string(e->property) +
                   "'; properties are read as " + std::string(name) + "." + std::string(e->property) + "()");
        return nullptr;
      }
      advance();
      if (tok_.kind != TokenKind::rparen) {
        error_here("property reads take no arguments; write " + std::string(name) + "." + std::string(e->property) + "()");
        return nullptr;
      }
      advance();
      return e;
    }
    default:
      error_here("expected an expression, found " + describe(tok_));
      return nullptr;
  }
}

}  // namespace eamos::lang
