#include "lang/ast.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <new>

namespace eamos::lang {

const char* op_text(Op op) {
  switch (op) {
    case Op::none: return "";
    case Op::neg: return "-";
    case Op::not_: return "!";
    case Op::add: return "+";
    case Op::sub: return "-";
    case Op::mul: return "*";
    case Op::div: return "/";
    case Op::lt: return "<";
    case Op::le: return "<=";
    case Op::gt: return ">";
    case Op::ge: return ">=";
    case Op::eq: return "==";
    case Op::ne: return "!=";
    case Op::and_: return "&&";
    case Op::or_: return "||";
  }
  return "";
}

Expr* ExprArena::make() {
  if (used_ == kChunk) {
    // Default-initialised bytes: nothing written, so the kernel maps no page until used.
    chunks_.push_back(std::unique_ptr<std::byte[]>(new std::byte[kChunk * sizeof(Expr)]));
    used_ = 0;
  }
  ++size_;
  return new (chunks_.back().get() + used_++ * sizeof(Expr)) Expr;
}

std::span<Expr* const> ExprArena::keep(std::span<Expr* const> list) {
  if (list.empty()) return {};
  if (list.size() > kListChunk) {  // longer than a chunk: an allocation of its own
    long_lists_.push_back(std::unique_ptr<Expr*[]>(new Expr*[list.size()]));
    std::copy(list.begin(), list.end(), long_lists_.back().get());
    return {long_lists_.back().get(), list.size()};
  }
  if (lists_used_ + list.size() > kListChunk) {
    lists_.push_back(std::unique_ptr<Expr*[]>(new Expr*[kListChunk]));  // uninitialised: untouched until used
    lists_used_ = 0;
  }
  Expr** at = lists_.back().get() + lists_used_;
  std::copy(list.begin(), list.end(), at);
  lists_used_ += list.size();
  return {at, list.size()};
}

int Mission::find_drone(const std::string& name) const {
  for (std::size_t i = 0; i < drones.size(); ++i)
    if (drones[i].name == name) return static_cast<int>(i);
  return -1;
}

int Mission::find_function(const std::string& name) const {
  for (std::size_t i = 0; i < functions.size(); ++i)
    if (functions[i].name == name) return static_cast<int>(i);
  return -1;
}

namespace {
void append_number(std::string& out, double v) {
  char buf[32];
  if (std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e15) {
    // What "%.0f" prints, without printf's cost: labels print a number per argument.
    if (v == 0 && std::signbit(v)) {
      out += "-0";
      return;
    }
    auto end = std::to_chars(buf, buf + sizeof buf, static_cast<long long>(v)).ptr;
    out.append(buf, end);
    return;
  }
  std::snprintf(buf, sizeof buf, "%g", v);
  out += buf;
}

// Go's binary precedence, used to print parentheses only where needed.
int precedence(Op op) {
  switch (op) {
    case Op::or_: return 1;
    case Op::and_: return 2;
    case Op::lt: case Op::le: case Op::gt: case Op::ge: case Op::eq: case Op::ne: return 3;
    case Op::add: case Op::sub: return 4;
    case Op::mul: case Op::div: return 5;
    default: return 6;
  }
}

void append_text(std::string& out, const Expr& e, int parent_precedence) {
  switch (e.kind) {
    case ExprKind::number: append_number(out, e.number); return;
    case ExprKind::boolean: out += e.boolean ? "true" : "false"; return;
    case ExprKind::property:
      out.append(e.drone);
      out += '.';
      out.append(e.property);
      out += "()";
      return;
    case ExprKind::name: out.append(e.drone); return;
    case ExprKind::unary:
      out += op_text(e.op);
      append_text(out, *e.lhs, 6);
      return;
    case ExprKind::binary: {
      int p = precedence(e.op);
      if (p < parent_precedence) out += '(';
      append_text(out, *e.lhs, p);
      out += ' ';
      out += op_text(e.op);
      out += ' ';
      append_text(out, *e.rhs, p + 1);
      if (p < parent_precedence) out += ')';
      return;
    }
  }
}
}  // namespace

std::string expr_text(const Expr& e) {
  std::string out;
  append_text(out, e, 0);
  return out;
}

void append_expr_text(std::string& out, const Expr& e) { append_text(out, e, 0); }

std::optional<double> literal_number(const Expr* e) {
  if (!e) return std::nullopt;
  if (e->kind == ExprKind::number) return e->number;
  if (e->kind == ExprKind::unary && e->op == Op::neg)
    if (auto v = literal_number(e->lhs)) return -*v;
  return std::nullopt;
}

}  // namespace eamos::lang
