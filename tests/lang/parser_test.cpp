// The lexer and parser on their own: Go's lexical rules, the grammar of Listing 1 and
// the expression precedence of Go.
#include <gtest/gtest.h>
#include <malloc.h>

#include "lang/lexer.h"
#include "lang/parser.h"

namespace eamos::lang {
namespace {

std::vector<TokenKind> kinds(const std::string& text) {
  SourceFile f("t.eamos", text);
  Diagnostics d;
  Lexer lx(f, d);
  std::vector<TokenKind> out;
  for (Token t = lx.next(); t.kind != TokenKind::end_of_file; t = lx.next()) out.push_back(t.kind);
  return out;
}

TEST(Lexer, NewlineAfterCloseParenEndsStatementLikeGo) {
  auto k = kinds("A.Arm()\nB.Arm()");
  ASSERT_EQ(k.size(), 12u);
  EXPECT_EQ(k[5], TokenKind::semicolon);
  EXPECT_EQ(k.back(), TokenKind::semicolon);  // at end of input too
}

TEST(Lexer, NewlineAfterCommaOrOperatorDoesNotEndStatement) {
  auto k = kinds("x ||\ny,\nz");
  EXPECT_EQ(k, (std::vector<TokenKind>{TokenKind::identifier, TokenKind::or_or, TokenKind::identifier,
                                       TokenKind::comma, TokenKind::identifier, TokenKind::semicolon}));
}

TEST(Lexer, CommentsAreSkippedAndBlockCommentWithNewlineEndsStatement) {
  auto k = kinds("a // one\nb /* x\n y */ c /* same line */ d");
  EXPECT_EQ(k, (std::vector<TokenKind>{TokenKind::identifier, TokenKind::semicolon, TokenKind::identifier,
                                       TokenKind::semicolon, TokenKind::identifier, TokenKind::identifier,
                                       TokenKind::semicolon}));
}

TEST(Lexer, IntegerAndDecimalLiterals) {
  auto k = kinds("42 4.5 .5 1e3 7");
  EXPECT_EQ(k, (std::vector<TokenKind>{TokenKind::integer, TokenKind::decimal, TokenKind::decimal,
                                       TokenKind::decimal, TokenKind::integer, TokenKind::semicolon}));
}

TEST(Lexer, UnknownBytesAreOneErrorPerRun) {
  SourceFile f("t.eamos", "a \x01\x02\x03 b");
  Diagnostics d;
  Lexer lx(f, d);
  while (lx.next().kind != TokenKind::end_of_file) {
  }
  EXPECT_EQ(d.error_count(), 1u);
}

Mission parse(const std::string& text, Diagnostics& d, SourceFile& f) {
  f = SourceFile("t.eamos", text);
  return parse_mission(f, d);
}

/// Bytes the process holds in malloc's blocks now.
std::size_t held_bytes() {
  struct mallinfo2 i = mallinfo2();
  return i.uordblks + i.hblkhd;
}

// A large mission holds millions of expressions: they live in the Mission's arena, a few
// thousand per allocation, and their names are views into the source text. Each its own
// allocation with copies of its names, a statement of three numbers held about 620 bytes.
TEST(Parser, AStatementOfThreeNumbersHoldsLessThan450Bytes) {
#ifdef EAMOS_SANITIZED
  GTEST_SKIP() << "a sanitizer's allocator keeps its blocks outside malloc's counters (mallinfo2)";
#endif
  constexpr int kStatements = 16384;  // a power of two: the body's vector has no slack
  std::string text = "var D0 Quad\nfunc INIT() {\n";
  for (int i = 0; i < kStatements; ++i) text += " D0.FlyTo(1, 2, 3)\n";
  text += "}\n";
  SourceFile f;
  Diagnostics d;
  std::size_t before = held_bytes();
  Mission m = parse(text, d, f);
  std::size_t held = held_bytes() - before - f.text.capacity() - f.line_starts.capacity() * sizeof(std::size_t);
  ASSERT_EQ(d.error_count(), 0u) << d.format();
  ASSERT_EQ(m.functions.size(), 1u);
  ASSERT_EQ(m.functions[0].body.size(), static_cast<std::size_t>(kStatements));
  EXPECT_EQ(m.expressions.size(), 3u * kStatements);
  EXPECT_LT(held / kStatements, 450u) << "bytes per statement";
}

TEST(Parser, ParsesDeclarationsFunctionsAndStatements) {
  SourceFile f;
  Diagnostics d;
  Mission m = parse("package p\nvar D1 Quad\nfunc INIT() {SEQ_a()}\nfunc SEQ_a() {\n D1.FlyTo(1, 2, 3)\n"
                    " async(SEQ_a); If(D1.X() > 1, SEQ_a, SEQ_a)\n}\n", d, f);
  EXPECT_FALSE(d.has_errors()) << d.format();
  EXPECT_EQ(m.package, "p");
  ASSERT_EQ(m.drones.size(), 1u);
  EXPECT_EQ(m.drones[0].type, "Quad");
  ASSERT_EQ(m.functions.size(), 2u);
  const auto& body = m.functions[1].body;
  ASSERT_EQ(body.size(), 3u);
  EXPECT_EQ(body[0].kind, StatementKind::action);
  EXPECT_EQ(body[0].args.size(), 3u);
  EXPECT_EQ(body[1].kind, StatementKind::async_call);
  EXPECT_EQ(body[2].callee, "If");
  EXPECT_EQ(body[2].args[1]->kind, ExprKind::name);
}

TEST(Parser, PrecedenceFollowsGo) {
  SourceFile f;
  Diagnostics d;
  Mission m = parse("var A Q\nfunc INIT() { PauseUntil(1 + 2 * 3 > 6 || !true && -A.X() < 0 == false) }\n", d, f);
  ASSERT_FALSE(d.has_errors()) << d.format();
  EXPECT_EQ(expr_text(*m.functions[0].body[0].args[0]), "1 + 2 * 3 > 6 || !true && -A.X() < 0 == false");
  const Expr& root = *m.functions[0].body[0].args[0];
  EXPECT_EQ(root.op, Op::or_);
  EXPECT_EQ(root.rhs->op, Op::and_);
  EXPECT_EQ(root.lhs->lhs->op, Op::add);
}

TEST(Parser, ParenthesesOverridePrecedence) {
  SourceFile f;
  Diagnostics d;
  Mission m = parse("var A Q\nfunc INIT() { A.FlyByX((1 + 2) * 3) }\n", d, f);
  ASSERT_FALSE(d.has_errors());
  EXPECT_EQ(m.functions[0].body[0].args[0]->op, Op::mul);
  EXPECT_EQ(expr_text(*m.functions[0].body[0].args[0]), "(1 + 2) * 3");
}

TEST(Parser, ReportsEverySyntaxErrorAndRecovers) {
  SourceFile f;
  Diagnostics d;
  Mission m = parse("var A Q\nfunc INIT() {\n A.Arm(\n A.Takeoff(3\n B..X()\n A.Land()\n}\nfunc SEQ_x() {}\n", d, f);
  EXPECT_GE(d.error_count(), 2u) << d.format();
  EXPECT_EQ(m.functions.size(), 2u);  // recovered to the next func
}

TEST(Parser, DeepNestingIsAnErrorNotAStackOverflow) {
  SourceFile f;
  Diagnostics d;
  std::string deep = "var A Q\nfunc INIT() { A.FlyByX(" + std::string(100000, '(') + "1" +
                     std::string(100000, ')') + ") }\n";
  parse(deep, d, f);
  ASSERT_TRUE(d.has_errors());
  EXPECT_NE(d.format().find("nested too deeply"), std::string::npos);
}

// Parentheses and operators count toward one limit: a sum of 101 terms in 100 parentheses
// is 201 levels deep, one more than allowed; with 100 terms it is at the limit.
TEST(Parser, ParenthesesAndOperatorsCountTowardOneDepthLimit) {
  auto nested_sum = [](int terms) {
    std::string s = std::string(100, '(') + "1";
    for (int i = 1; i < terms; ++i) s += "+1";
    return "var A Q\nfunc INIT() { A.FlyByX(" + s + std::string(100, ')') + ") }\n";
  };
  SourceFile f, g;
  Diagnostics at_limit, over;
  parse(nested_sum(100), at_limit, f);
  EXPECT_FALSE(at_limit.has_errors()) << at_limit.format();
  parse(nested_sum(101), over, g);
  ASSERT_TRUE(over.has_errors());
  EXPECT_NE(over.format().find("nested too deeply"), std::string::npos) << over.format().substr(0, 300);
}

TEST(Parser, NewlineInsideArgumentListIsAllowed) {
  SourceFile f;
  Diagnostics d;
  parse("var A Q\nfunc INIT() { If(A.X() > 1\n , SEQ_a\n , SEQ_b\n ) }\n", d, f);
  EXPECT_FALSE(d.has_errors()) << d.format();
}

}  // namespace
}  // namespace eamos::lang
