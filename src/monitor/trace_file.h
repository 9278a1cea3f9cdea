#pragma once
// Reading a finished trace (JSON Lines, docs/trace.md) for `eamos monitor`. The file comes
// from outside: every line is checked, and what reaches the page is re-serialised from the
// checked values, never the file's bytes.
#include <istream>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace eamos::monitor {

struct LoadedTrace {
  std::optional<nlohmann::json> header;  ///< the schema v1 header line, when the trace has one
  std::vector<std::string> events;       ///< every other line, re-serialised (one JSON object each)
  std::vector<std::string> errors;       ///< "file:line: error: what; how to fix"
  std::vector<std::string> warnings;
};

/// Reads the trace named `name` from `in`. Stops listing errors after `max_errors` (0: all).
LoadedTrace read_trace(const std::string& name, std::istream& in, std::size_t max_errors = 50);

/// Checks one event object; returns "" when it is usable, else what is wrong with it.
std::string check_event(const nlohmann::json& j);

}  // namespace eamos::monitor
