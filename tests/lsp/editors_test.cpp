// The editor files of editors/: the TextMate grammar (run by a small TextMate tokenizer over
// a mission that has every kind of token), the VS Code extension's manifest and script,
// the Vim syntax file (loaded in the real `vim -es` and asked for each word's group), and
// `eamos lsp` in two real clients: Vim with Debian's ALE and Neovim's built-in client, each
// through the configuration editors/vim ships.
// The grammar and the Vim file name the language's control structures and the catalog
// documents every standard capability: both are checked against the compiler's own tables.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <filesystem>
#include <map>
#include <optional>
#include <regex>

#include "fleet/catalog.h"
#include "lang/ast.h"
#include "lang/checker.h"
#include "lsp/lsp_support.h"

namespace eamos {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kEditors = fs::path(EAMOS_SOURCE_DIR) / "editors";
const fs::path kMission = fs::path(EAMOS_TEST_DATA) / "data" / "highlight.eamos";

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

// A TextMate rule, flattened: `match` with a name and captures, or `begin`/`end`.
struct Rule {
  std::regex match, end;
  bool block = false;
  std::string name;
  std::map<int, std::string> captures;
};

void flatten(const json& grammar, const json& node, std::vector<Rule>& out) {
  if (node.contains("include")) {
    std::string key = node["include"].get<std::string>().substr(1);
    ASSERT_TRUE(grammar["repository"].contains(key)) << "include of a missing rule #" << key;
    return flatten(grammar, grammar["repository"][key], out);
  }
  if (node.contains("patterns")) {
    for (const json& p : node["patterns"]) flatten(grammar, p, out);
    return;
  }
  Rule r;
  r.block = node.contains("begin");
  // Only what ECMAScript and Oniguruma read alike: a pattern std::regex refuses is a fault.
  r.match = std::regex(node[r.block ? "begin" : "match"].get<std::string>());
  if (r.block) r.end = std::regex(node["end"].get<std::string>());
  r.name = node.value("name", "");
  if (node.contains("captures"))
    for (auto& [k, v] : node["captures"].items()) r.captures[std::stoi(k)] = v["name"];
  out.push_back(std::move(r));
}

// Each line's scopes, byte by byte: at each position the rule whose match starts first wins
// (the earlier rule on a tie), as a TextMate engine does.
std::vector<std::vector<std::string>> tokenize(const std::vector<Rule>& rules, const std::vector<std::string>& lines) {
  std::vector<std::vector<std::string>> scopes;
  const Rule* open = nullptr;
  for (const std::string& line : lines) {
    std::vector<std::string> s(line.size() + 1);
    std::size_t pos = 0;
    while (pos <= line.size()) {
      auto flags = pos > 0 ? std::regex_constants::match_prev_avail : std::regex_constants::match_default;
      std::smatch m;
      if (open) {
        bool closed = std::regex_search(line.begin() + pos, line.end(), m, open->end, flags);
        std::size_t stop = closed ? pos + m.position(0) + m.length(0) : line.size();
        for (std::size_t i = pos; i < stop; ++i) s[i] = open->name;
        pos = stop;
        if (!closed) break;
        open = nullptr;
        continue;
      }
      const Rule* best = nullptr;
      std::smatch best_m;
      for (const Rule& r : rules)
        if (std::regex_search(line.begin() + pos, line.end(), m, r.match, flags) && m.length(0) > 0 &&
            (!best || m.position(0) < best_m.position(0))) {
          best = &r;
          best_m = m;
        }
      if (!best) break;
      std::size_t start = pos + best_m.position(0), stop = start + best_m.length(0);
      for (std::size_t i = start; i < stop; ++i) s[i] = best->name;
      for (auto& [group, name] : best->captures)
        if (best_m[group].matched)
          for (std::size_t i = pos + best_m.position(group); i < pos + best_m.position(group) + best_m.length(group);
               ++i)
            s[i] = name;
      if (best->block) open = best;
      pos = stop;
    }
    scopes.push_back(std::move(s));
  }
  return scopes;
}

json read_json(const fs::path& p) {
  json j = json::parse(eamos_test::slurp(p.string()), nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << p << " is not valid JSON";
  return j;
}

TEST(TextMateGrammar, ColoursEveryKindOfTokenOfAMission) {
  json grammar = read_json(kEditors / "textmate" / "eamos.tmLanguage.json");
  ASSERT_TRUE(grammar.is_object());
  EXPECT_EQ(grammar["scopeName"], "source.eamos");
  EXPECT_EQ(grammar["fileTypes"], json::array({"eamos"}));
  std::vector<Rule> rules;
  flatten(grammar, grammar, rules);
  ASSERT_FALSE(HasFailure());
  std::vector<std::string> lines = lines_of(eamos_test::slurp(kMission.string()));
  auto scopes = tokenize(rules, lines);
  auto scope = [&](int line, const std::string& word, int nth = 0) {
    std::size_t at = lines[line - 1].find(word);
    while (nth-- > 0) at = lines[line - 1].find(word, at + 1);
    return at == std::string::npos ? "(no '" + word + "')" : scopes[line - 1][at];
  };
  EXPECT_EQ(scope(1, "Every"), "comment.line.double-slash.eamos");
  EXPECT_EQ(scope(1, "/*"), "comment.line.double-slash.eamos");
  EXPECT_EQ(scope(2, "package"), "keyword.other.package.eamos");
  EXPECT_EQ(scope(4, "var"), "storage.type.var.eamos");
  EXPECT_EQ(scope(4, "Lead"), "variable.other.drone.declaration.eamos");
  EXPECT_EQ(scope(4, "Scout"), "entity.name.type.eamos");
  EXPECT_EQ(scope(7, "block"), "comment.block.eamos");
  EXPECT_EQ(scope(8, "over"), "comment.block.eamos");
  EXPECT_EQ(scope(9, "func"), "storage.type.function.eamos");
  EXPECT_EQ(scope(9, "INIT"), "entity.name.function.eamos");
  EXPECT_EQ(scope(9, "SEQ_main"), "entity.name.function.block.eamos");
  EXPECT_EQ(scope(11, "SEQ_main"), "entity.name.function.eamos");
  EXPECT_EQ(scope(13, "If"), "keyword.control.eamos");
  EXPECT_EQ(scope(13, "Lead"), "variable.other.drone.eamos");
  EXPECT_EQ(scope(13, "."), "punctuation.accessor.eamos");
  EXPECT_EQ(scope(13, "Sensor1"), "support.function.capability.eamos");
  EXPECT_EQ(scope(13, ">="), "keyword.operator.eamos");
  EXPECT_EQ(scope(13, "100"), "constant.numeric.eamos");
  EXPECT_EQ(scope(13, "&&"), "keyword.operator.eamos");
  EXPECT_EQ(scope(13, "!"), "keyword.operator.eamos");
  EXPECT_EQ(scope(13, "Landed"), "support.function.capability.eamos");
  EXPECT_EQ(scope(13, "SEQ_far"), "entity.name.function.block.eamos");
  EXPECT_EQ(scope(13, ","), "punctuation.separator.comma.eamos");
  EXPECT_EQ(scope(14, "RepeatFor"), "keyword.control.eamos");
  EXPECT_EQ(scope(14, "true"), "constant.language.boolean.eamos");
  EXPECT_EQ(scope(14, "3"), "constant.numeric.eamos");
  EXPECT_EQ(scope(15, "async"), "keyword.control.async.eamos");
  EXPECT_EQ(scope(16, "2.5"), "constant.numeric.eamos");
  EXPECT_EQ(scope(18, "4e1"), "constant.numeric.eamos");
  EXPECT_EQ(scope(18, "/"), "keyword.operator.eamos");
  EXPECT_EQ(scope(18, ";"), "punctuation.terminator.statement.eamos");
  EXPECT_EQ(scope(18, "{"), "punctuation.section.block.begin.eamos");
}

TEST(TextMateGrammar, NamesEveryControlStructureOfTheLanguage) {
  json grammar = read_json(kEditors / "textmate" / "eamos.tmLanguage.json");
  std::regex control(grammar["repository"]["control"]["match"].get<std::string>());
  for (int k = static_cast<int>(lang::ControlKind::If); k <= static_cast<int>(lang::ControlKind::DoWhileSync); ++k) {
    std::string name = lang::control_name(static_cast<lang::ControlKind>(k));
    EXPECT_TRUE(std::regex_match(name, control)) << name;
    EXPECT_EQ(std::string(lang::control_usage(static_cast<lang::ControlKind>(k))).rfind(name + "(", 0), 0u) << name;
  }
  EXPECT_FALSE(std::regex_match(std::string("Iff"), control));
}

TEST(CapabilityDocs, EveryStandardCapabilityHasWordsAndUnitsForEachArgument) {
  for (const auto& a : fleet::standard_actions()) {
    const fleet::CapabilityDoc* doc = fleet::capability_doc(a.name);
    ASSERT_NE(doc, nullptr) << a.name;
    EXPECT_FALSE(doc->summary.empty()) << a.name;
    EXPECT_EQ(static_cast<int>(doc->params.size()), *std::max_element(a.arities.begin(), a.arities.end())) << a.name;
    for (const auto& p : doc->params) EXPECT_FALSE(p.unit.empty() || p.meaning.empty()) << a.name << " " << p.name;
  }
  for (const auto& p : fleet::standard_properties()) {
    const fleet::CapabilityDoc* doc = fleet::capability_doc(p.name);
    ASSERT_NE(doc, nullptr) << p.name;
    EXPECT_EQ(doc->unit.empty(), p.unit.empty()) << p.name << ": a unit in words exactly when the catalog has one";
  }
  ASSERT_NE(fleet::capability_doc("Sensor12"), nullptr);
  EXPECT_EQ(fleet::capability_doc("Sensor12")->name, "SensorK");
  EXPECT_EQ(fleet::capability_doc("Sensor0"), nullptr);
  EXPECT_EQ(fleet::capability_doc("Fly"), nullptr);
}

TEST(VsCodeExtension, DeclaresTheLanguageItsGrammarAndStartsEamosLsp) {
  fs::path dir = kEditors / "vscode";
  json manifest = read_json(dir / "package.json");
  ASSERT_TRUE(manifest.is_object());
  const json& language = manifest["contributes"]["languages"][0];
  EXPECT_EQ(language["id"], "eamos");
  EXPECT_EQ(language["extensions"], json::array({".eamos"}));
  EXPECT_FALSE(read_json(dir / language["configuration"].get<std::string>()).is_discarded());
  const json& grammar = manifest["contributes"]["grammars"][0];
  EXPECT_EQ(grammar["scopeName"], "source.eamos");
  // The extension's grammar is a copy of editors/textmate's (a link would not survive a
  // Windows checkout or every packager), and must stay the same.
  EXPECT_EQ(eamos_test::slurp((dir / grammar["path"].get<std::string>()).string()),
            eamos_test::slurp((kEditors / "textmate" / "eamos.tmLanguage.json").string()));
  EXPECT_TRUE(manifest["dependencies"].contains("vscode-languageclient"));
  std::string script = eamos_test::slurp((dir / manifest["main"].get<std::string>()).string());
  EXPECT_NE(script.find("args: ['lsp']"), std::string::npos);
  if (std::system("command -v node >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "node is not installed: extension.js not parsed";
  std::string cmd = "node --check '" + (dir / "extension.js").string() + "' 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
}

TEST(VimSyntax, LoadsInVimAndGivesEachWordItsGroup) {
  if (std::system("command -v vim >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "vim is not installed (Debian: apt-get install vim); editors/vim not checked";
  std::string out = (fs::temp_directory_path() / ("eamos-vim-" + std::to_string(getpid()))).string();
  std::string cmd = "vim -es -N -u NONE -i NONE --cmd 'set rtp^=" + (kEditors / "vim").string() +
                    "' -c 'filetype plugin on' -c 'syntax on' -c 'edit " + kMission.string() + "' -c \"let g:out='" +
                    out + "'\" -c 'source " + (fs::path(EAMOS_TEST_DATA) / "vim_groups.vim").string() +
                    "' -c 'qa!' </dev/null";
  int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << cmd;
  std::string text = eamos_test::slurp(out);
  std::remove(out.c_str());
  std::vector<std::string> got = lines_of(text);
  ASSERT_FALSE(got.empty()) << cmd;
  EXPECT_EQ(got.front(), "filetype eamos");
  EXPECT_EQ(got.back(), "errmsg ");
  auto has = [&](const std::string& line) { return std::find(got.begin(), got.end(), line) != got.end(); };
  for (const char* expected :
       {"1:1 // eamosComment",           "2:1 package eamosKeyword",    "4:1 var eamosKeyword",
        "4:10 Scout eamosType",          "7:1 /* eamosComment",         "8:4 over eamosComment",
        "9:6 INIT eamosBlock",           "11:6 SEQ_main eamosBlock",    "13:3 If eamosControl",
        "13:11 Sensor1 eamosCapability", "13:21 >= eamosOperator",      "13:24 100 eamosNumber",
        "13:28 && eamosOperator",        "13:31 ! eamosOperator",       "13:37 Landed eamosCapability",
        "13:47 SEQ_far eamosBlock",      "14:3 RepeatFor eamosControl", "14:13 true eamosBoolean",
        "15:3 async eamosAsync",         "16:12 2 eamosNumber",         "18:22 Takeoff eamosCapability",
        "18:47 - eamosOperator",         "18:48 4e1 eamosNumber"})
    EXPECT_TRUE(has(expected)) << expected << "\n" << text;
}

// Runs a shell command with EAMOS_BIN, EAMOS_OUT and `env` in its environment; returns
// its exit status (-1 when it did not exit) and what it wrote to EAMOS_OUT, line by line.
std::pair<int, std::vector<std::string>> run_client(const std::string& command,
                                                    std::map<std::string, std::string> env = {}) {
  std::string out = (fs::temp_directory_path() / ("eamos-client-" + std::to_string(getpid()))).string();
  env["EAMOS_BIN"] = EAMOS_BINARY;
  env["EAMOS_OUT"] = out;
  std::string prefix;
  for (const auto& [k, v] : env) prefix += k + "='" + v + "' ";
  int raw = std::system((prefix + command + " </dev/null >/dev/null 2>&1").c_str());
  std::string text = eamos_test::slurp(out);
  std::remove(out.c_str());
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, lines_of(text)};
}

const fs::path kSessionData = fs::path(EAMOS_TEST_DATA) / "data";
const std::string kFlyByXError =
    "drone 'Lead' of type 'Scout' has no capability 'FlyByX'; see `eamos check --list-capabilities`";

TEST(VimWithAle, ShowsTheDiagnosticsOfEamosLspWithTheFleetFile) {
  if (std::system("command -v vim >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "vim is not installed (Debian: apt-get install vim)";
  if (!fs::exists("/usr/share/vim/vimfiles/pack/dist-bundle/opt/ale"))
    GTEST_SKIP() << "ALE is not installed (Debian: apt-get install vim-ale); editors/vim/ale_linters not checked";
  std::string command = "vim -N -u NONE -i NONE -es --cmd 'set rtp^=" + (kEditors / "vim").string() +
                        "' -c 'packadd ale' -c 'filetype plugin on' -c 'edit " +
                        (kSessionData / "mission.eamos").string() + "' -c 'source " +
                        (fs::path(EAMOS_TEST_DATA) / "ale_probe.vim").string() + "' -c 'qa!'";
  auto [status, got] = run_client(command, {{"EAMOS_FLEET", (kSessionData / "fleet.yaml").string()}});
  ASSERT_EQ(status, 0) << command;
  // The fleet file took effect: Scout has no FlyByX there (the generic type has).
  std::vector<std::string> expected = {"22:23 E " + kFlyByXError};
  fs::path source(EAMOS_SOURCE_DIR);
  expected.push_back("root " + (fs::exists(source / ".git") ? source : kSessionData).string());
  EXPECT_EQ(got, expected) << command;
}

TEST(NeovimLsp, ShowsDiagnosticsHoverAndDefinitionFromEamosLsp) {
  if (std::system("command -v nvim >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "Neovim is not installed (Debian: apt-get install neovim); editors/vim/lua/eamos.lua not checked";
  std::string setup =
      "lua require(\"eamos\").setup({cmd = {os.getenv(\"EAMOS_BIN\"), \"lsp\"}, fleet = os.getenv(\"EAMOS_FLEET\")})";
  std::string command = "nvim --headless -u NONE -i NONE --cmd 'set rtp^=" + (kEditors / "vim").string() + "' -c '" +
                        setup + "' -c 'filetype plugin on' -c 'edit " + (kSessionData / "mission.eamos").string() +
                        "' -c 'luafile " + (fs::path(EAMOS_TEST_DATA) / "nvim_probe.lua").string() + "' -c 'qa!'";
  // Hover on FlyTo (line 12), definition of the PAR_up called on line 10 (0-based below).
  auto [status, got] = run_client(command, {{"EAMOS_FLEET", (kSessionData / "fleet.yaml").string()},
                                            {"HOVER_LINE", "11"},
                                            {"HOVER_CHAR", "8"},
                                            {"DEF_LINE", "9"},
                                            {"DEF_CHAR", "3"}});
  ASSERT_EQ(status, 0) << command;
  ASSERT_EQ(got.size(), 3u) << command;
  EXPECT_EQ(got[0], "diagnostic 21:22 " + kFlyByXError);
  EXPECT_EQ(got[1],
            "hover ```eamos Lead.FlyTo(x, y, z) ``` Motion action of `Scout`: fly to a position in the mission frame.  "
            "- `x`: east of the frame's origin, in metres - `y`: north of the frame's origin, in metres - `z`: up "
            "from home ground level, in metres ");
  EXPECT_EQ(got[2], "definition 16:5");
}

}  // namespace
}  // namespace eamos
