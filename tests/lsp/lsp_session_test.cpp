// `eamos lsp` driven as a subprocess with the recorded sessions of tests/lsp/sessions/:
// NAME.in holds the client's messages, one JSON per line (framed by the test), and
// NAME.out the server's answers, pretty-printed, with the exit status last. In NAME.in:
//   `# args: ...`        arguments after `eamos lsp` (the first such line)
//   `# ...`, blank       comments
//   `RAW "..."`          bytes sent as they are (a JSON string with \r\n escapes): framing faults
//   a line that is no JSON is framed and sent as it is: a malformed message
// and in any JSON string `${DATA}` stands for tests/lsp/data, `@include FILE` (the whole
// string) for the text of tests/lsp/data/FILE. The transcript writes `${DATA}` back and the
// server's version as `${VERSION}`. Regenerate after an intended change with
// EAMOS_UPDATE_GOLDEN=1 and review the diff.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <regex>

#include "lsp/lsp_support.h"

namespace eamos {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kDir = fs::path(EAMOS_TEST_DATA);
const std::string kData = (kDir / "data").string();

void replace_all(std::string& s, const std::string& from, const std::string& to) {
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
}

void substitute(json& j) {
  if (j.is_string()) {
    std::string s = j.get<std::string>();
    if (s.rfind("@include ", 0) == 0) {
      j = eamos_test::slurp(kData + "/" + s.substr(9));
      return;
    }
    replace_all(s, "${DATA}", kData);
    j = s;
  }
  if (j.is_structured())
    for (auto& v : j) substitute(v);
}

// A path as a file: URI spells it (RFC 3986: unreserved characters and '/' stay).
std::string percent_encoded(const std::string& path) {
  std::string out;
  char hex[4];
  for (unsigned char c : path) {
    if (std::isalnum(c) || c == '/' || c == '-' || c == '.' || c == '_' || c == '~') {
      out += static_cast<char>(c);
    } else {
      std::snprintf(hex, sizeof hex, "%%%02X", c);
      out += hex;
    }
  }
  return out;
}

struct Session {
  std::vector<std::string> args;
  std::string input;
};

Session load_session(const std::string& name) {
  Session s;
  std::istringstream lines(eamos_test::slurp((kDir / "sessions" / (name + ".in")).string()));
  std::string line;
  bool have_args = false;
  while (std::getline(lines, line)) {
    if (line.rfind("# args:", 0) == 0 && !have_args) {
      std::istringstream words(line.substr(7));
      for (std::string w; words >> w;) {
        replace_all(w, "${DATA}", kData);
        s.args.push_back(w);
      }
      have_args = true;
    } else if (line.empty() || line[0] == '#') {
      continue;
    } else if (line.rfind("RAW ", 0) == 0) {
      s.input += json::parse(line.substr(4)).get<std::string>();
    } else {
      json j = json::parse(line, nullptr, false);
      if (!j.is_discarded()) substitute(j);
      s.input += eamos_test::frame(j.is_discarded() ? line : j.dump());
    }
  }
  return s;
}

std::string transcript(const eamos_test::LspRun& run) {
  std::string out;
  for (json m : run.messages) {
    if (m.contains("result") && m["result"].is_object() && m["result"].contains("serverInfo"))
      m["result"]["serverInfo"]["version"] = "${VERSION}";
    std::string text = m.dump(2, ' ', false, json::error_handler_t::replace);
    replace_all(text, percent_encoded(kData), "${DATA}");  // in a URI the server made
    replace_all(text, kData, "${DATA}");
    out += text + "\n";
  }
  return out + "exit " + std::to_string(run.status) + "\n";
}

std::vector<std::string> sessions() {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(kDir / "sessions"))
    if (e.path().extension() == ".in") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

class RecordedSession : public ::testing::TestWithParam<std::string> {};

TEST_P(RecordedSession, ServerAnswersAsRecorded) {
  std::string name = GetParam();
  Session s = load_session(name);
  eamos_test::LspRun run = eamos_test::run_lsp(s.args, s.input);
  ASSERT_NE(run.status, -1) << name << ": eamos lsp did not exit normally (a signal?)";
  ASSERT_EQ(run.problem, "") << name;
  std::string actual = transcript(run);
  fs::path expected = kDir / "sessions" / (name + ".out");
  if (std::getenv("EAMOS_UPDATE_GOLDEN")) {
    std::ofstream(expected, std::ios::binary) << actual;
    return;
  }
  EXPECT_EQ(eamos_test::slurp(expected.string()), actual) << "session " << name;
}

INSTANTIATE_TEST_SUITE_P(Sessions, RecordedSession, ::testing::ValuesIn(sessions()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace eamos
