#include "lsp/document.h"

#include <algorithm>

#include "graph/pipeline.h"
#include "lang/lexer.h"

namespace eamos::lsp {

namespace {

std::vector<Token> lex(const SourceFile& file) {
  Diagnostics ignored;  // the check reports the same problems, once
  ignored.max_errors = 0;
  lang::Lexer lexer(file, ignored);
  std::vector<Token> tokens;
  for (;;) {
    lang::Token t = lexer.next();
    if (t.kind == lang::TokenKind::end_of_file) break;
    if (t.kind == lang::TokenKind::semicolon && t.text != ";") continue;
    tokens.push_back({t.kind, t.loc, static_cast<int>(t.text.size()), std::string(t.text)});
  }
  return tokens;
}

}  // namespace

CheckResult update(Document& doc, std::string text, const std::string& fleet_path, fleet::Fleet& fleet) {
  doc.source = std::make_shared<SourceFile>(doc.path, std::move(text));
  doc.tokens = lex(*doc.source);
  // As graph::compile_file does for `eamos check`: a fleet file with errors still yields the
  // parts that parsed, and the mission is checked against them.
  Diagnostics diags;
  fleet = fleet::Fleet{};
  if (!fleet_path.empty()) fleet::load_fleet(fleet_path, fleet, diags);
  graph::Compilation c;
  graph::compile(doc.source, fleet, diags, c, {}, graph::Keep::deployment_graphs);
  doc.mission = std::move(c.mission);

  CheckResult r;
  Published* last = nullptr;  // the diagnostic an attached note belongs to
  for (const Diagnostic& d : diags.items()) {
    if (d.attached && last) {
      last->notes.push_back(d);
      continue;
    }
    bool fleet_file = d.has_file && !fleet_path.empty() && d.path == fleet_path && d.path != doc.path;
    std::vector<Published>& list = fleet_file ? r.fleet : r.mission;
    list.push_back({d, {}});
    last = &list.back();
  }
  if (diags.saturated()) {
    Diagnostic d;
    d.message = "stopped listing after " + std::to_string(diags.max_errors) +
                " errors; fix these first, and the next ones show";
    r.mission.push_back({d, {}});
  }
  auto by_place = [](const Published& a, const Published& b) {
    return std::make_pair(a.diagnostic.loc.line, a.diagnostic.loc.col) <
           std::make_pair(b.diagnostic.loc.line, b.diagnostic.loc.col);
  };
  std::stable_sort(r.mission.begin(), r.mission.end(), by_place);
  std::stable_sort(r.fleet.begin(), r.fleet.end(), by_place);
  return r;
}

namespace {

nlohmann::json one_diagnostic(const Diagnostic& d, Encoding enc) {
  // 1 error, 2 warning, 3 information: a note is information beside its error.
  int severity = d.severity == Severity::error ? 1 : d.severity == Severity::warning ? 2 : 3;
  return {{"range", to_json(word_range(d.source_line, d.loc, enc))},
          {"severity", severity},
          {"source", "eamos"},
          {"message", d.message}};
}

std::string where(const Diagnostic& note) {
  std::string at = note.path;
  if (note.loc.known()) at += ":" + std::to_string(note.loc.line) + ":" + std::to_string(note.loc.col);
  return at;
}

}  // namespace

nlohmann::json diagnostics_json(const std::vector<Published>& items, const PublishOptions& options) {
  nlohmann::json out = nlohmann::json::array();
  for (const Published& p : items) {
    nlohmann::json d = one_diagnostic(p.diagnostic, options.encoding);
    std::string parent_uri = options.uri_of(p.diagnostic);
    std::vector<nlohmann::json> beside;
    for (const Diagnostic& n : p.notes) {
      // relatedInformation needs a place in a file; a note without one ends the message.
      if (options.related_information && n.has_file) {
        d["relatedInformation"].push_back(
            {{"location",
              {{"uri", options.uri_of(n)}, {"range", to_json(word_range(n.source_line, n.loc, options.encoding))}}},
             {"message", n.message}});
      } else if (n.has_file && p.diagnostic.has_file && options.uri_of(n) == parent_uri) {
        beside.push_back(one_diagnostic(n, options.encoding));
      } else {
        d["message"] = d["message"].get<std::string>() + "\nnote: " + (n.has_file ? where(n) + ": " : "") + n.message;
      }
    }
    out.push_back(std::move(d));
    for (nlohmann::json& b : beside) out.push_back(std::move(b));
  }
  return out;
}

std::string_view line_of(const Document& doc, int line) {
  return doc.source ? doc.source->line(line) : std::string_view{};
}

Range token_range(const Document& doc, const Token& t, Encoding enc) {
  std::string_view line = line_of(doc, t.loc.line);
  Position start = to_position(line, t.loc, enc);
  Position end = to_position(line, {t.loc.line, t.loc.col + t.length}, enc);
  return {start, end};
}

}  // namespace eamos::lsp
