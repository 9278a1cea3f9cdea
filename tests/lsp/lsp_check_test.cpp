// The editor shows what `eamos check` prints: every mission of tests/lang/diagnostics/ is
// opened in the real `eamos lsp` and its published diagnostics (position, severity,
// message, and the notes printed under each as its relatedInformation, with their places)
// are compared with that mission's golden `eamos check` output (NAME.expected, which
// tests/lang keeps true). A fleet file's diagnostics go to the fleet file's URI. A client
// that does not show relatedInformation gets each note beside its diagnostic instead.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <regex>

#include "diag/source.h"
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

std::string strip_colour(const std::string& text) {
  static const std::regex escape("\x1b\\[[0-9;]*m");
  return std::regex_replace(text, escape, "");
}

// "LINE:COL: severity: message" per diagnostic `eamos check` printed about `file`, sorted,
// each followed by " [note FILE:LINE:COL: message]" for each note printed under it (the
// notes after an error or warning belong to it; one before any stands alone). With
// `unlocated`, also those it tied to no file, which the editor shows at 1:1 of the mission.
// `notes_apart`: as a client without relatedInformation gets them, each note of `file` its
// own entry.
std::vector<std::string> from_check(const std::string& expected, const std::string& file, bool unlocated,
                                    bool notes_apart = false) {
  static const std::regex located_re(R"(^([^ :][^:]*):(\d+):(\d+): (error|warning|note): (.*)$)");
  static const std::regex unlocated_re(R"(^(error|warning|note): (.*)$)");
  std::vector<std::string> out;
  std::istringstream lines(strip_colour(expected));
  std::smatch m;
  bool in_diagnostic = false, ours = false;  // after an error or warning; about `file`
  for (std::string line; std::getline(lines, line);) {
    if (std::regex_match(line, m, located_re)) {
      std::string place = m[2].str() + ":" + m[3].str() + ": ";
      if (m[4] == "note" && in_diagnostic && !notes_apart) {
        if (ours) out.back() += " [note " + m[1].str() + ":" + place + m[5].str() + "]";
        continue;
      }
      if (m[4] != "note") in_diagnostic = true;
      ours = m[1] == file;
      if (ours) out.push_back(place + (m[4] == "note" ? "information" : m[4].str()) + ": " + m[5].str());
    } else if (std::regex_match(line, m, unlocated_re)) {
      in_diagnostic = m[1] != "note";
      ours = unlocated;
      if (unlocated) out.push_back("1:1: " + (m[1] == "note" ? "information" : m[1].str()) + ": " + m[2].str());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The same from a publishDiagnostics (UTF-8 positions: LSP's 0-based line and byte column),
// a related place named by its file in tests/lang/diagnostics.
std::vector<std::string> from_lsp(const json& diagnostics) {
  static const char* severity[] = {"", "error", "warning", "information"};
  auto place = [](const json& range) {
    int line = range["start"]["line"], col = range["start"]["character"];
    return std::to_string(line + 1) + ":" + std::to_string(col + 1) + ": ";
  };
  std::vector<std::string> out;
  for (const json& d : diagnostics) {
    std::string entry = place(d["range"]) + severity[d["severity"].get<int>()] + ": " + d["message"].get<std::string>();
    for (const json& r : d.value("relatedInformation", json::array())) {
      std::string file = fs::path(r["location"]["uri"].get<std::string>()).filename().string();
      entry += " [note " + file + ":" + place(r["location"]["range"]) + r["message"].get<std::string>() + "]";
    }
    out.push_back(entry);
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
void expect_same_as_check(const std::vector<Case>& group, const std::string& fleet, bool related = true) {
  json init = {{"capabilities",
                {{"general", {{"positionEncodings", {"utf-8", "utf-16"}}}},
                 {"textDocument", {{"publishDiagnostics", {{"relatedInformation", related}}}}}}}};
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
    EXPECT_EQ(from_check(expected, c.name + ".eamos", true, !related), from_lsp(mission)) << c.name;
    if (c.fleet) {
      std::string fleet_uri = uri(c.name, ".fleet.yaml");
      json fleet_diagnostics = published.count(fleet_uri) ? published[fleet_uri] : json::array();
      EXPECT_EQ(from_check(expected, c.name + ".fleet.yaml", false, !related), from_lsp(fleet_diagnostics))
          << c.name;
    }
  }
}

// NAME.args asking for JSON or SARIF: that golden tests the document format, not what is
// found; its mission is also a text case (color_always, whose escapes are stripped).
bool text_golden(const Case& c) {
  fs::path args = kCases / (c.name + ".args");
  return !fs::exists(args) || eamos_test::slurp(args.string()).find("--diagnostics-format") == std::string::npos;
}

// A mission that is not UTF-8 cannot travel in an LSP message (JSON text is UTF-8: a client
// sends its bytes as U+FFFD), so the server never sees what `eamos check` reports there.
bool utf8_mission(const Case& c) {
  std::string text = eamos_test::slurp((kCases / (c.name + ".eamos")).string());
  return first_invalid_utf8(text, 0, text.size()) == std::string_view::npos;
}

TEST(LspDiagnostics, EveryDiagnosticOfEamosCheckIsPublishedAtItsPlace) {
  std::vector<Case> plain;
  for (const Case& c : cases()) {
    if (!text_golden(c) || !utf8_mission(c)) continue;
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

// Vim's ALE, for one, does not show relatedInformation: there "first defined here" is its
// own diagnostic at its place, as `eamos check` prints it.
TEST(LspDiagnostics, NotesArePublishedBesideTheirDiagnosticToAClientWithoutRelatedInformation) {
  std::vector<Case> with_notes;
  for (const Case& c : cases())
    if (!c.fleet && text_golden(c) && utf8_mission(c) &&
        eamos_test::slurp((kCases / (c.name + ".expected")).string()).find(": note: ") != std::string::npos)
      with_notes.push_back(c);
  ASSERT_GE(with_notes.size(), 3u);
  expect_same_as_check(with_notes, "", false);
}

}  // namespace
}  // namespace eamos
