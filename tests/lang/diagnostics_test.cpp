// One mission file per diagnostic under tests/lang/diagnostics/: NAME.eamos next to
// NAME.expected, the exact text `eamos check` prints (paths relative to that folder).
// Regenerate after an intended change with EAMOS_UPDATE_GOLDEN=1 and review the diff.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "graph/pipeline.h"

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

TEST_P(Diagnostic, MatchesExpectedOutput) {
  fs::path dir = fs::path(EAMOS_TEST_DATA) / "diagnostics";
  std::string name = GetParam();
  auto source = std::make_shared<SourceFile>(name + ".eamos", read_file(dir / (name + ".eamos")));
  fleet::Fleet fleet;
  Diagnostics diags;
  if (fs::exists(dir / (name + ".fleet.yaml"))) {
    auto fleet_source = std::make_shared<SourceFile>(name + ".fleet.yaml", read_file(dir / (name + ".fleet.yaml")));
    fleet::parse_fleet(fleet_source, fleet, diags);
  }
  graph::Compilation c;
  graph::compile(source, fleet, diags, c);
  std::string actual = diags.format();
  ASSERT_FALSE(actual.empty()) << name << " produced no diagnostic at all";
  fs::path expected_path = dir / (name + ".expected");
  if (std::getenv("EAMOS_UPDATE_GOLDEN")) {
    std::ofstream(expected_path, std::ios::binary) << actual;
    return;
  }
  EXPECT_EQ(read_file(expected_path), actual) << "for " << name;
}

INSTANTIATE_TEST_SUITE_P(Files, Diagnostic, ::testing::ValuesIn(cases()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace eamos
