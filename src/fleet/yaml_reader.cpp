#include "fleet/yaml_reader.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <yaml-cpp/eventhandler.h>

#include "diag/printable.h"

namespace eamos::fleet {

SourceLocation location_of(const YAML::Mark& mark) {
  if (mark.is_null() || mark.line < 0 || mark.column < 0) return {};
  return {mark.line + 1, mark.column + 1};
}

namespace {

bool is_identifier(const std::string& s) {
  auto alpha = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; };
  auto digit = [](char c) { return c >= '0' && c <= '9'; };
  if (s.empty() || !alpha(s[0])) return false;
  return std::all_of(s.begin(), s.end(), [&](char c) { return alpha(c) || digit(c); });
}

// A quoted scalar ("5") is text the author chose to write as text; taking it as a number
// would hide a mistake such as `sensors: "2"` meant as a name.
bool quoted(const YAML::Node& node) { return node.Tag() == "!"; }

}  // namespace

std::string describe(const YAML::Node& node) {
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a map";
  if (node.IsScalar()) return "'" + diag::printable(node.Scalar()) + "'";
  return "nothing";
}

std::string one_of(const std::vector<std::string>& choices) {
  std::string out;
  for (std::size_t i = 0; i < choices.size(); ++i) {
    if (i > 0) out += i + 1 == choices.size() ? " or " : ", ";
    out += choices[i];
  }
  return out;
}

namespace {

// Only where each document starts matters: a document that starts where the previous one
// did means the parser consumed nothing.
struct DocumentStarts : YAML::EventHandler {
  std::vector<YAML::Mark> starts;
  void OnDocumentStart(const YAML::Mark& mark) override { starts.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

}  // namespace

bool load_one_document(const std::string& text, YAML::Node& out, const SourceFile* file,
                       Diagnostics& diags) {
  // yaml-cpp 0.7 does not consume a token that cannot start a node (a leading ',' or ']'):
  // it reports an empty document there, again and again, so YAML::LoadAll never returns
  // (jbeder/yaml-cpp#1040, fixed upstream after 0.8). Walking at most three documents
  // bounds that loop, and a start that did not move names the stray token.
  std::istringstream in(text);
  YAML::Parser parser(in);
  DocumentStarts documents;
  for (int i = 0; i < 3 && parser.HandleNextDocument(documents); ++i) {
  }
  const auto& starts = documents.starts;
  for (std::size_t i = 1; i < starts.size(); ++i) {
    if (starts[i].pos != starts[i - 1].pos) continue;
    std::size_t pos = static_cast<std::size_t>(std::max(starts[i].pos, 0));
    diags.error(file, location_of(starts[i]),
                "YAML syntax error: unexpected '" + diag::printable(text.substr(pos, 1)) +
                    "'; remove it or quote the text it belongs to");
    return false;
  }
  if (starts.size() > 1) {
    std::size_t pos = static_cast<std::size_t>(std::max(starts[1].pos, 0));
    // Without a `---` the first document ended early: text the parser could not fit in.
    bool separator = text.compare(pos, 3, "---") == 0;
    diags.error(file, location_of(starts[1]),
                separator ? "a fleet file holds one YAML document; remove the `---` and merge "
                            "the rest into the first"
                          : "YAML syntax error: the file should have ended before this text; "
                            "check the indentation and brackets above");
    return false;
  }
  out = YAML::Load(text);
  return true;
}

void YamlReader::error(const YAML::Node& at, const std::string& message) {
  diags.error(file, location_of(at.Mark()), message);
}

bool YamlReader::map(const YAML::Node& node, const std::string& what) {
  if (node.IsMap()) return true;
  if (!node.IsNull()) error(node, what + " must be a map of `key: value` lines; got " + describe(node));
  return false;
}

std::string YamlReader::key(const YAML::Node& key, std::set<std::string>& seen,
                            const std::string& where) {
  if (!key.IsScalar()) {
    error(key, "keys of " + where + " must be plain names; got " + describe(key));
    return "";
  }
  const std::string& text = key.Scalar();
  if (!seen.insert(text).second) {
    error(key, "'" + diag::printable(text) + "' appears twice in " + where + "; remove one of them");
    return "";
  }
  return text;
}

std::string YamlReader::field(const YAML::Node& k, const std::vector<std::string>& allowed,
                              std::set<std::string>& seen, const std::string& where) {
  std::string text = key(k, seen, where);
  if (text.empty() || std::find(allowed.begin(), allowed.end(), text) != allowed.end()) return text;
  std::string near = closest_match(text, allowed);
  error(k, "unknown key '" + diag::printable(text) + "' in " + where +
               (near.empty() ? "; expected " + one_of(allowed) : "; did you mean '" + near + "'?"));
  return "";
}

std::string YamlReader::name(const YAML::Node& k, std::set<std::string>& seen,
                             const std::string& where) {
  std::string text = key(k, seen, where);
  if (text.empty() || is_identifier(text)) return text;
  error(k, "'" + diag::printable(text) + "' in " + where +
               " cannot be written in a mission; use letters, digits and '_', not starting with a digit");
  return "";
}

bool YamlReader::number(const YAML::Node& node, const std::string& what, double& out) {
  double value = 0;
  bool ok = node.IsScalar() && !quoted(node) && YAML::convert<double>::decode(node, value);
  if (!ok || !std::isfinite(value)) {
    error(node, what + " must be a number; got " + describe(node));
    return false;
  }
  out = value;
  return true;
}

bool YamlReader::whole_number(const YAML::Node& node, const std::string& what, long long& out) {
  long long value = 0;
  if (!node.IsScalar() || quoted(node) || !YAML::convert<long long>::decode(node, value)) {
    error(node, what + " must be a whole number; got " + describe(node));
    return false;
  }
  out = value;
  return true;
}

bool YamlReader::text(const YAML::Node& node, const std::string& what, std::string& out) {
  if (!node.IsScalar()) {
    error(node, what + " must be text; got " + describe(node));
    return false;
  }
  out = node.Scalar();
  return true;
}

bool YamlReader::vec3(const YAML::Node& node, const std::string& what, Vec3& out) {
  if (!node.IsSequence() || node.size() != 3) {
    error(node, what + " must be a list of three numbers [x, y, z]; got " +
                    (node.IsSequence() ? "a list of " + std::to_string(node.size()) : describe(node)));
    return false;
  }
  double v[3] = {0, 0, 0};
  bool ok = true;
  for (std::size_t i = 0; i < 3; ++i) ok = number(node[i], what + " [" + "xyz"[i] + "]", v[i]) && ok;
  if (ok) out = {v[0], v[1], v[2]};
  return ok;
}

bool YamlReader::choice(const YAML::Node& node, const std::string& what,
                        const std::vector<std::string>& choices, std::string& out) {
  std::string value;
  if (!text(node, what, value)) return false;
  if (std::find(choices.begin(), choices.end(), value) != choices.end()) {
    out = value;
    return true;
  }
  std::string near = closest_match(value, choices);
  error(node, "unknown " + what + " '" + diag::printable(value) + "'; " +
                  (near.empty() ? "use " + one_of(choices) : "did you mean '" + near + "'?"));
  return false;
}

}  // namespace eamos::fleet
