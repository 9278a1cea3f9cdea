#include "monitor/trace_file.h"

#include <cmath>

namespace eamos::monitor {

namespace {

// Lines longer than this are not a trace event (a header with a large mission is allowed).
constexpr std::size_t max_line_bytes = 64u << 20;
// More events than this would not fit in a browser anyway.
constexpr std::size_t max_events = 5'000'000;
// An eamos trace line nests four levels (the header's drones and homes); unknown fields
// are kept, so some room, but a bound: parsing is iterative, serialising again is not.
constexpr int max_nesting = 64;

struct TraceLine {
  bool got = false;       ///< false at the end of the input
  bool too_long = false;  ///< longer than max_line_bytes: skipped to its end, `text` empty
  bool newline = false;   ///< it ended with '\n' (a run killed mid-write leaves one without)
};

/// The next line of `in` into `text`, holding at most max_line_bytes of it: a corrupt file of
/// one endless line costs that much memory, not the file's size.
TraceLine next_line(std::istream& in, std::string& text) {
  TraceLine r;
  text.clear();
  std::streambuf* buf = in.rdbuf();
  for (int c = buf->sbumpc(); c != std::char_traits<char>::eof(); c = buf->sbumpc()) {
    r.got = true;
    if (c == '\n') {
      r.newline = true;
      break;
    }
    if (r.too_long) continue;
    if (text.size() == max_line_bytes) {
      r.too_long = true;
      text.clear();
      text.shrink_to_fit();
      continue;
    }
    text.push_back(static_cast<char>(c));
  }
  return r;
}

/// True when brackets outside strings nest deeper than `limit` in `line`: looked at before
/// the line is parsed, so that nothing deeper is ever built.
bool nests_deeper_than(const std::string& line, int limit) {
  int depth = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    char c = line[i];
    if (c == '"') {
      // To the closing quote, over escapes.
      for (++i; i < line.size() && line[i] != '"'; ++i)
        if (line[i] == '\\') ++i;
    } else if (c == '[' || c == '{') {
      if (++depth > limit) return true;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return false;
}

bool finite_number(const nlohmann::json& v) { return v.is_number() && std::isfinite(v.get<double>()); }

std::string check_field(const nlohmann::json& j, const char* key, bool (*ok)(const nlohmann::json&),
                        const char* what) {
  auto it = j.find(key);
  if (it == j.end() || ok(*it)) return "";
  return std::string("\"") + key + "\" must be " + what;
}

bool is_string(const nlohmann::json& v) { return v.is_string(); }
bool is_bool(const nlohmann::json& v) { return v.is_boolean(); }
bool is_count(const nlohmann::json& v) { return v.is_number_integer() && v.get<long long>() >= 0; }
bool is_number_or_bool(const nlohmann::json& v) { return v.is_boolean() || finite_number(v); }
bool number_or_null(const nlohmann::json& v) { return v.is_null() || finite_number(v); }

std::string check_header(const nlohmann::json& j) {
  if (!j.contains("version") || !j["version"].is_number_integer()) return "the header's \"version\" must be an integer";
  if (j["version"].get<long long>() != 1)
    return "trace schema version " + j["version"].dump() + " is not supported (this eamos reads version 1)";
  for (const char* key : {"mission", "source", "fleet", "run"})
    if (std::string e = check_field(j, key, is_string, "a string"); !e.empty()) return e;
  for (const char* key : {"path", "paths", "violations"})
    if (std::string e = check_field(j, key, is_count, "a whole number >= 0"); !e.empty()) return e;
  if (j.contains("drones")) {
    if (!j["drones"].is_array()) return "\"drones\" must be a list";
    for (const auto& d : j["drones"]) {
      if (!d.is_object() || !d.contains("name") || !d["name"].is_string()) return "every drone needs a \"name\"";
      if (d.contains("home") && (!d["home"].is_array() || d["home"].size() != 3 ||
                                 !finite_number(d["home"][0]) || !finite_number(d["home"][1]) ||
                                 !finite_number(d["home"][2])))
        return "a drone's \"home\" must be [x, y, z]";
    }
  }
  return "";
}

}  // namespace

std::string check_event(const nlohmann::json& j) {
  if (!j.is_object()) return "a trace line must be a JSON object";
  if (!j.contains("t") || !finite_number(j["t"]) || j["t"].get<double>() < 0)
    return "\"t\" (mission seconds, >= 0) is missing or not a number";
  if (!j.contains("event") || !j["event"].is_string()) return "\"event\" is missing or not a string";
  for (const char* key : {"drone", "name", "text", "outcome", "reason", "kind", "from", "to", "mode"})
    if (std::string e = check_field(j, key, is_string, "a string"); !e.empty()) return e;
  for (const char* key : {"line", "node", "instance"})
    if (std::string e = check_field(j, key, is_count, "a whole number >= 0"); !e.empty()) return e;
  for (const char* key : {"x", "y", "z", "battery", "sent", "received"})
    if (std::string e = check_field(j, key, finite_number, "a number"); !e.empty()) return e;
  // null: the vehicle reports no heading (docs/trace.md, "Telemetry").
  if (std::string e = check_field(j, "heading", number_or_null, "a number or null"); !e.empty()) return e;
  for (const char* key : {"armed", "landed"})
    if (std::string e = check_field(j, key, is_bool, "true or false"); !e.empty()) return e;
  if (std::string e = check_field(j, "value", is_number_or_bool, "a number or true/false"); !e.empty()) return e;
  if (j["event"] == "header") return check_header(j);
  return "";
}

LoadedTrace read_trace(const std::string& name, std::istream& in, std::size_t max_errors) {
  LoadedTrace out;
  std::string line;
  std::size_t number = 0;
  std::size_t total_errors = 0;
  auto error = [&](std::size_t at, const std::string& what) {
    ++total_errors;
    if (max_errors == 0 || out.errors.size() < max_errors)
      out.errors.push_back(name + ":" + std::to_string(at) + ": error: " + what);
  };
  for (TraceLine read; (read = next_line(in, line)).got;) {
    ++number;
    bool last_without_newline = !read.newline;
    if (read.too_long) {
      error(number, "line longer than 64 MiB; this is not an eamos trace");
      continue;
    }
    if (line.empty()) continue;
    if (nests_deeper_than(line, max_nesting)) {
      error(number, "nested more than " + std::to_string(max_nesting) +
                        " levels deep; an eamos trace line nests a few (docs/trace.md)");
      continue;
    }
    nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded()) {
      // A run killed while writing leaves half a last line: the rest is still a trace.
      if (last_without_newline) {
        out.warnings.push_back(name + ":" + std::to_string(number) +
                               ": warning: the last line is cut off (the run ended while writing it); ignored");
        continue;
      }
      error(number, "not valid JSON; every line of a trace is one JSON object (eamos run --trace writes them)");
      continue;
    }
    if (std::string what = check_event(j); !what.empty()) {
      error(number, what + "; see docs/trace.md for the trace's fields");
      continue;
    }
    if (j["event"] == "header") {
      if (out.header || !out.events.empty()) error(number, "a header may only be the first line");
      else out.header = j;
      continue;
    }
    if (out.events.size() >= max_events) {
      error(number, "more than 5,000,000 events; the monitor replays at most that many");
      break;
    }
    out.events.push_back(j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  }
  if (total_errors > out.errors.size())
    out.errors.push_back(name + ": error: " + std::to_string(total_errors - out.errors.size()) +
                         " more error(s) not listed");
  return out;
}

}  // namespace eamos::monitor
