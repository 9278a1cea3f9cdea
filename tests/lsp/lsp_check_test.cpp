// The editor shows what `eamos check` prints: every mission of tests/lang/diagnostics/ is
// opened in the real `eamos lsp` and its published diagnostics (position, severity,
// message) are compared with that mission's golden `eamos check` output (NAME.expected,
// which tests/lang keeps true). A fleet file's diagnostics go to the fleet file's URI.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <regex>

#include "lsp/lsp_support.h"

namespace eamos {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kCases = fs::path(EAMOS_SOURCE_DIR) / "tests" / "lang" / "diagnostics";

struct Case {
  std::string name;
  bool fleet = false;
};

std::vector<Case> cases() {
  std::vector<Case> out;
  for (const auto& e : fs::directory_iterator(kCases))
    if (e.path().extension() == ".eamos") {
      std::string name = e.path().stem().string();
      out.push_back({name, fs::exists(kCases / (name + ".fleet.yaml"))});
    }
  std::sort(out.begin(), out.end(), [](const Case& a, const Case& b) { return a.name < b.name; });
  return out;
}

std::string uri(const std::string& name, const char* ext) { return "file://" + (kCases / (name + ext)).string(); }

// "LINE:COL: severity: message" per diagnostic `eamos check` printed about `file`, sorted;
// with `unlocated`, also those it tied to no file, which the editor shows at 1:1 of the mission.
std::vector<std::string> from_check(const std::string& expected, const std::string& file, bool unlocated) {
  static const std::regex located_re(R"(^([^ :][^:]*):(\d+):(\d+): (error|warning|note): (.*)$)");
  static const std::regex unlocated_re(R"(^(error|warning|note): (.*)$)");
  std::vector<std::string> out;
  std::istringstream lines(expected);
  std::smatch m;
  for (std::string line; std::getline(lines, line);) {
    if (std::regex_match(line, m, located_re) && m[1] == file)
      out.push_back(m[2].str() + ":" + m[3].str() + ": " + m[4].str() + ": " + m[5].str());
    else if (unlocated && std::regex_match(line, m, unlocated_re))
      out.push_back("1:1: " + m[1].str() + ": " + m[2].str());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The same from a publishDiagnostics (UTF-8 positions: LSP's 0-based line and byte column).
std::vector<std::string> from_lsp(const json& diagnostics) {
  static const char* severity[] = {"", "error", "warning", "note"};
  std::vector<std::string> out;
  for (const json& d : diagnostics) {
    int line = d["range"]["start"]["line"], col = d["range"]["start"]["character"];
    out.push_back(std::to_string(line + 1) + ":" + std::to_string(col + 1) + ": " + severity[d["severity"].get<int>()] +
                  ": " + d["message"].get<std::string>());
  }
  std::sort(out.begin(), out.end());
  return out;
}

json message(const std::string& method, json params, int id = 0) {
  json m = {{"jsonrpc", "2.0"}, {"method", method}, {"params", std::move(params)}};
  if (id) m["id"] = id;
  return m;
}

// One server for every case that shares a fleet setting: the cases without a fleet file
// together, each case with one alone (the fleet file is per session, as in an editor).
void expect_same_as_check(const std::vector<Case>& group, const std::string& fleet) {
  json init = {{"capabilities", {{"general", {{"positionEncodings", {"utf-8", "utf-16"}}}}}}};
  std::string input = eamos_test::frame(message("initialize", init, 1).dump());
  for (const Case& c : group)
    input += eamos_test::frame(
        message("textDocument/didOpen", {{"textDocument",
                                          {{"uri", uri(c.name, ".eamos")},
                                           {"languageId", "eamos"},
                                           {"version", 1},
                                           {"text", eamos_test::slurp((kCases / (c.name + ".eamos")).string())}}}})
            .dump(-1, ' ', false, json::error_handler_t::replace));
  input +=
      eamos_test::frame(message("shutdown", nullptr, 2).dump()) + eamos_test::frame(message("exit", nullptr).dump());
  eamos_test::LspRun run = eamos_test::run_lsp(
      fleet.empty() ? std::vector<std::string>{} : std::vector<std::string>{"--fleet", fleet}, input);
  ASSERT_EQ(run.status, 0);
  ASSERT_EQ(run.problem, "");
  std::map<std::string, json> published;
  for (const json& m : run.messages)
    if (m.value("method", "") == "textDocument/publishDiagnostics")
      published[m["params"]["uri"]] = m["params"]["diagnostics"];
  for (const Case& c : group) {
    std::string expected = eamos_test::slurp((kCases / (c.name + ".expected")).string());
    ASSERT_TRUE(published.count(uri(c.name, ".eamos"))) << c.name;
    const json& mission = published[uri(c.name, ".eamos")];
    EXPECT_EQ(from_check(expected, c.name + ".eamos", true), from_lsp(mission)) << c.name;
    if (c.fleet) {
      std::string fleet_uri = uri(c.name, ".fleet.yaml");
      json fleet_diagnostics = published.count(fleet_uri) ? published[fleet_uri] : json::array();
      EXPECT_EQ(from_check(expected, c.name + ".fleet.yaml", false), from_lsp(fleet_diagnostics)) << c.name;
    }
  }
}

TEST(LspDiagnostics, EveryDiagnosticOfEamosCheckIsPublishedAtItsPlace) {
  std::vector<Case> plain;
  for (const Case& c : cases()) {
    if (!c.fleet) {
      plain.push_back(c);
      continue;
    }
    SCOPED_TRACE(c.name);
    expect_same_as_check({c}, (kCases / (c.name + ".fleet.yaml")).string());
  }
  ASSERT_GT(plain.size(), 100u);
  expect_same_as_check(plain, "");
}

}  // namespace
}  // namespace eamos
