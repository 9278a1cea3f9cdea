// Whole-file behaviour of the checker: every error in one run, robustness against hostile
// input, Listing 2 as the paper printed it. Single rules live in diagnostics/ files.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "graph/pipeline.h"

namespace eamos {
namespace {

struct Result {
  bool ok;
  std::string text;
  std::size_t errors;
  std::size_t warnings;
};

Result check(const std::string& text) {
  graph::Compilation c;
  Diagnostics d;
  d.max_errors = 0;
  bool ok = graph::compile(std::make_shared<SourceFile>("m.eamos", text), fleet::Fleet{}, d, c);
  return {ok, d.format(), d.error_count(), d.warning_count()};
}

std::string read_file(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Checker, Listing2CompilesWithOnlyTheOrbitPreemptionWarning) {
  Result r = check(read_file(std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos"));
  EXPECT_TRUE(r.ok) << r.text;
  EXPECT_EQ(r.warnings, 1u) << r.text;
  EXPECT_NE(r.text.find("'Drone2' may run two motion actions at the same time: Land"), std::string::npos)
      << r.text;
}

TEST(Checker, ReportsEveryErrorOfAFileInOneRun) {
  Result r = check(
      "var A Quad\nfunc INIT() {\n  B.Arm()\n  A.Fly()\n  A.Takeoff()\n  SEQ_missing()\n"
      "  If(A.X(), SEQ_x, SEQ_x)\n}\nfunc SEQ_x() { A.Arm() }\nfunc bad() {}\n");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.errors, 6u) << r.text;
}

TEST(Checker, BinaryGarbageIsReportedNotCrashed) {
  std::string garbage;
  for (int i = 0; i < 20000; ++i) garbage += static_cast<char>((i * 7919) % 256);
  Result r = check(garbage);
  EXPECT_FALSE(r.ok);
  EXPECT_GT(r.errors, 0u);
}

TEST(Checker, ExponentialExpansionIsRejectedBeforeBuildingIt) {
  // Each block calls the next twice: 2^40 instances if expanded.
  std::string text = "var A Quad\nfunc INIT() { SEQ_0() }\n";
  for (int i = 0; i < 40; ++i)
    text += "func SEQ_" + std::to_string(i) + "() { SEQ_" + std::to_string(i + 1) + "(); SEQ_" +
            std::to_string(i + 1) + "() }\n";
  text += "func SEQ_40() { A.Arm() }\n";
  Result r = check(text);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.text.find("mission expands to more than"), std::string::npos) << r.text;
}

TEST(Checker, VeryLongCallChainIsAnErrorNotAStackOverflow) {
  std::string text = "var A Quad\nfunc INIT() { SEQ_0() }\n";
  for (int i = 0; i < 50000; ++i)
    text += "func SEQ_" + std::to_string(i) + "() { SEQ_" + std::to_string(i + 1) + "() }\n";
  text += "func SEQ_50000() { A.Arm() }\n";
  Result r = check(text);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.text.find("nest more than"), std::string::npos);
}

TEST(Checker, MutualRecursionIsReportedOnce) {
  Result r = check("var A Quad\nfunc INIT() { SEQ_a() }\nfunc SEQ_a() { SEQ_b() }\nfunc SEQ_b() { If(true, SEQ_a, SEQ_a) }\n");
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.errors, 1u) << r.text;
  EXPECT_NE(r.text.find("recursion"), std::string::npos);
}

TEST(Checker, ErrorCarriesFileLineColumnSourceLineAndCaret) {
  Result r = check("var A Quad\nfunc INIT() {\n\tA.Tkeoff(3)\n}\n");
  EXPECT_EQ(r.text,
            "m.eamos:3:4: error: drone 'A' of type 'Quad' has no capability 'Tkeoff'; did you mean 'Takeoff'?\n"
            " \tA.Tkeoff(3)\n"
            " \t  ^\n");
}

}  // namespace
}  // namespace eamos
