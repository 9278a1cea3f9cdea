#include "diag/report.h"

#include <cctype>
#include <string_view>

#include <nlohmann/json.hpp>

namespace eamos {

namespace {

using Json = nlohmann::ordered_json;

Json one_json(const Diagnostic& d) {
  Json j;
  j["file"] = d.has_file ? Json(d.path) : Json(nullptr);
  j["line"] = d.loc.line;
  j["column"] = d.loc.col;
  j["end_column"] = d.loc.known() ? d.loc.col + std::max(d.length, 1) : 0;
  j["severity"] = severity_name(d.severity);
  j["message"] = d.message;
  if (d.has_file && d.loc.known()) j["source_line"] = d.source_line;
  return j;
}

std::string dump(const Json& j) { return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n"; }

// A diagnostic and the notes attached after it.
std::vector<std::vector<const Diagnostic*>> groups_of(const Diagnostics& diags) {
  std::vector<std::vector<const Diagnostic*>> groups;
  for (const Diagnostic& d : diags.items()) {
    if (d.attached && !groups.empty()) groups.back().push_back(&d);
    else groups.push_back({&d});
  }
  return groups;
}

// The byte column of a line as a code-point column (SARIF's unicodeCodePoints).
int code_point_column(const std::string& line, int byte_col) {
  int col = 1;
  for (int i = 0; i + 1 < byte_col && static_cast<std::size_t>(i) < line.size(); ++i)
    col += (static_cast<unsigned char>(line[i]) & 0xC0) != 0x80;
  return col + std::max(0, byte_col - 1 - static_cast<int>(line.size()));
}

std::string uri_escape(const std::string& path) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : path) {
    if (std::isalnum(c) || std::string_view("/-._~").find(static_cast<char>(c)) != std::string_view::npos) {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

Json sarif_location(const Diagnostic& d) {
  Json artifact;
  if (!d.path.empty() && d.path[0] == '/') {
    artifact["uri"] = "file://" + uri_escape(d.path);
  } else {
    artifact["uri"] = uri_escape(d.path);
    artifact["uriBaseId"] = "%SRCROOT%";
  }
  Json physical;
  physical["artifactLocation"] = artifact;
  if (d.loc.known()) {
    int start = code_point_column(d.source_line, d.loc.col);
    int end = code_point_column(d.source_line, d.loc.col + std::max(d.length, 1));
    physical["region"] = {{"startLine", d.loc.line}, {"startColumn", start}, {"endColumn", end},
                          {"snippet", {{"text", d.source_line}}}};
  }
  return {{"physicalLocation", physical}};
}

}  // namespace

std::string diagnostics_json(const Diagnostics& diags) {
  Json list = Json::array();
  for (const auto& g : groups_of(diags)) {
    Json j = one_json(*g[0]);
    Json notes = Json::array();
    for (std::size_t i = 1; i < g.size(); ++i) notes.push_back(one_json(*g[i]));
    j["notes"] = notes;
    list.push_back(j);
  }
  Json out;
  out["diagnostics"] = list;
  out["errors"] = diags.error_count();
  out["warnings"] = diags.warning_count();
  out["not_shown"] = diags.dropped();
  return dump(out);
}

std::string diagnostics_sarif(const Diagnostics& diags, const std::string& tool, const std::string& version,
                              const std::string& working_dir) {
  Json results = Json::array();
  for (const auto& g : groups_of(diags)) {
    const Diagnostic& d = *g[0];
    Json r;
    r["level"] = severity_name(d.severity);
    r["message"] = {{"text", d.message}};
    r["locations"] = d.has_file ? Json::array({sarif_location(d)}) : Json::array();
    Json related = Json::array();
    for (std::size_t i = 1; i < g.size(); ++i) {
      if (!g[i]->has_file) continue;
      Json loc = sarif_location(*g[i]);
      loc["id"] = static_cast<int>(i - 1);
      loc["message"] = {{"text", g[i]->message}};
      related.push_back(loc);
    }
    if (!related.empty()) r["relatedLocations"] = related;
    results.push_back(r);
  }
  Json driver = {{"name", tool}, {"version", version}};
  Json run;
  run["tool"] = {{"driver", driver}};
  std::string root = working_dir.empty() || working_dir.back() == '/' ? working_dir : working_dir + "/";
  run["originalUriBaseIds"] = {{"%SRCROOT%", {{"uri", "file://" + uri_escape(root)}}}};
  run["columnKind"] = "unicodeCodePoints";
  run["results"] = results;
  Json log;
  log["$schema"] = "https://json.schemastore.org/sarif-2.1.0.json";
  log["version"] = "2.1.0";
  log["runs"] = Json::array({run});
  return dump(log);
}

}  // namespace eamos
