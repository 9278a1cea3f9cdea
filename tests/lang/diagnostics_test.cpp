// One mission file per diagnostic under tests/lang/diagnostics/: NAME.eamos next to
// NAME.expected, the exact text `eamos check NAME.eamos [--fleet NAME.fleet.yaml] [ARGS]`
// prints when run in that folder, ARGS from NAME.args when there is one (--color=always,
// --diagnostics-format=json|sarif: the same diagnostics in colour and as documents; the
// folder's absolute path in a SARIF log is written <dir>). The test runs the real binary, as a user does: a harness that
// calls the library could keep alive what the CLI frees, and hide a crash the user sees.
// Regenerate after an intended change with EAMOS_UPDATE_GOLDEN=1 and review the diff.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "support/run_eamos.h"

namespace eamos {
namespace {

namespace fs = std::filesystem;

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> cases() {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(fs::path(EAMOS_TEST_DATA) / "diagnostics"))
    if (e.path().extension() == ".eamos") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

class Diagnostic : public ::testing::TestWithParam<std::string> {};

TEST_P(Diagnostic, EamosCheckPrintsExpectedOutput) {
  fs::path dir = fs::path(EAMOS_TEST_DATA) / "diagnostics";
  std::string name = GetParam();
  std::string args = "check " + name + ".eamos";
  if (fs::exists(dir / (name + ".fleet.yaml"))) args += " --fleet " + name + ".fleet.yaml";
  if (fs::exists(dir / (name + ".args"))) {
    std::string extra = read_file(dir / (name + ".args"));
    args += " " + extra.substr(0, extra.find('\n'));
  }
  eamos_test::Output run = eamos_test::run_eamos(args, {}, dir.string());
  ASSERT_NE(run.status, -1) << name << ": eamos did not exit normally (a signal?)\n" << run.out;
  for (std::size_t at; (at = run.out.find("file://" + dir.string())) != std::string::npos;)
    run.out.replace(at, 7 + dir.string().size(), "file://<dir>");
  bool has_error = run.out.find(": error: ") != std::string::npos ||
                   run.out.find("\x1b[1;31merror:") != std::string::npos ||
                   run.out.find("\"severity\": \"error\"") != std::string::npos ||
                   run.out.find("\"level\": \"error\"") != std::string::npos;
  EXPECT_EQ(run.status, has_error ? 1 : 0) << name << ":\n" << run.out;
  EXPECT_EQ(run.out.find("what()"), std::string::npos) << name << ": an exception escaped";
  fs::path expected_path = dir / (name + ".expected");
  if (std::getenv("EAMOS_UPDATE_GOLDEN")) {
    std::ofstream(expected_path, std::ios::binary) << run.out;
    return;
  }
  EXPECT_EQ(read_file(expected_path), run.out) << "for " << name;
}

INSTANTIATE_TEST_SUITE_P(Files, Diagnostic, ::testing::ValuesIn(cases()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace eamos
