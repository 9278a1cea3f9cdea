// Every mission the documentation shows is one the tool accepts: each fenced block of
// README.md and docs/*.md marked `go` or `eamos` (or unmarked with a line starting
// `func INIT(`) goes through `eamos check`; a complete one (it declares a drone and has
// INIT) also through `eamos verify` and `eamos run`. A line `<!-- eamos-test: ARGS -->` right
// before the fence adds arguments (a fleet) to all three.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;

struct DocMission {
  std::string doc;   ///< relative to the source tree
  int line = 0;      ///< of the opening fence
  std::string text;
  std::string args;  ///< from an eamos-test comment
};

std::vector<DocMission> doc_missions() {
  fs::path root = EAMOS_SOURCE_DIR;
  std::vector<fs::path> docs = {root / "README.md"};
  for (const auto& e : fs::directory_iterator(root / "docs"))
    if (e.path().extension() == ".md") docs.push_back(e.path());
  std::sort(docs.begin() + 1, docs.end());
  std::vector<DocMission> found;
  const std::regex fence(R"(^\s*(```+|~~~+)\s*([\w-]*).*$)");
  const std::regex directive(R"(^<!--\s*eamos-test:\s*(.*?)\s*-->\s*$)");
  for (const fs::path& doc : docs) {
    std::ifstream in(doc);
    std::vector<std::string> lines;
    for (std::string l; std::getline(in, l);) lines.push_back(l);
    for (std::size_t i = 0; i < lines.size(); ++i) {
      std::smatch m;
      if (!std::regex_match(lines[i], m, fence)) continue;
      std::string marker = m[1], lang = m[2];
      std::size_t end = i + 1;
      std::string body;
      while (end < lines.size() && lines[end].find(marker) == std::string::npos) body += lines[end++] + "\n";
      bool has_init = std::regex_search(body, std::regex(R"((^|\n)func INIT\()"));
      if (lang == "go" || lang == "eamos" || (lang.empty() && has_init)) {
        DocMission d{fs::relative(doc, root).string(), static_cast<int>(i + 1), body, ""};
        std::smatch dm;
        if (i > 0 && std::regex_match(lines[i - 1], dm, directive)) d.args = dm[1];
        found.push_back(d);
      }
      i = end;
    }
  }
  return found;
}

std::string name_of(const DocMission& d) {
  std::string n = d.doc + "_" + std::to_string(d.line);
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
}

class DocMissionTest : public ::testing::TestWithParam<DocMission> {};

TEST_P(DocMissionTest, IsAcceptedByCheckAndFliesWhenComplete) {
  const DocMission& d = GetParam();
  fs::path file = fs::temp_directory_path() / ("eamos-doc-" + std::to_string(getpid()) + "-" + name_of(d) + ".eamos");
  std::ofstream(file) << d.text;
  std::string where = d.doc + ":" + std::to_string(d.line);
  std::string args = " " + file.string() + (d.args.empty() ? "" : " " + d.args);
  eamos_test::Output check = eamos_test::run_eamos("check" + args, {}, EAMOS_SOURCE_DIR);
  EXPECT_EQ(check.status, 0) << where << ": eamos check fails on the mission shown there:\n" << check.out;
  bool complete = d.text.find("func INIT(") != std::string::npos && d.text.find("var ") != std::string::npos;
  if (complete && check.status == 0) {
    eamos_test::Output verify = eamos_test::run_eamos("verify -q" + args, {}, EAMOS_SOURCE_DIR);
    EXPECT_EQ(verify.status, 0) << where << ": eamos verify:\n" << verify.out;
    eamos_test::Output run = eamos_test::run_eamos("run -q" + args, {}, EAMOS_SOURCE_DIR);
    EXPECT_EQ(run.status, 0) << where << ": eamos run:\n" << run.out;
    EXPECT_NE(run.out.find("mission completed"), std::string::npos) << where << ":\n" << run.out;
  }
  fs::remove(file);
}

INSTANTIATE_TEST_SUITE_P(Docs, DocMissionTest, ::testing::ValuesIn(doc_missions()),
                         [](const auto& info) { return name_of(info.param); });

// The extraction itself: the README's mission and the language guide's are among those found,
// so a change of fence style cannot quietly leave every doc untested.
TEST(DocMissions, FindsTheReadmeAndLanguageGuideMissions) {
  std::vector<DocMission> all = doc_missions();
  auto from = [&](const std::string& doc) {
    return std::count_if(all.begin(), all.end(), [&](const DocMission& d) { return d.doc == doc; });
  };
  EXPECT_GE(from("README.md"), 1);
  EXPECT_GE(from("docs/language.md"), 1);
}

}  // namespace
