// Reading a trace file (JSON Lines, docs/trace.md) into Python: checked line by line with
// the schema's own check (trace::check_trace) before any of it is handed over.
#include <cstdint>
#include <sstream>

#include "bindings.h"
#include "diag/file_read.h"
#include "trace/trace_schema.h"

namespace eamos::python {

namespace {

/// The most problems one load lists; a file that is not a trace at all would otherwise give
/// one per line.
constexpr std::size_t kMaxTraceErrors = 50;

/// The largest trace read: a thousand drones for an hour at 5 Hz of telemetry (about 59 kB
/// per drone-minute) is 3.5 GB.
constexpr std::uint64_t kMaxTraceBytes = std::uint64_t{8} << 30;

/// "line 12: what" → "PATH:12: error: what".
std::string located(const std::string& path, const std::string& error) {
  const std::string prefix = "line ";
  if (error.rfind(prefix, 0) == 0) {
    std::size_t colon = error.find(':');
    if (colon != std::string::npos)
      return path + ":" + error.substr(prefix.size(), colon - prefix.size()) + ": error:" + error.substr(colon + 1);
  }
  return path + ": error: " + error;
}

/// A file whose first line is not a JSON object is no trace at all (a mission file, a summary
/// .json): said once, instead of once per line.
bool first_line_is_object(const std::string& text) {
  std::string first = text.substr(0, text.find('\n'));
  nlohmann::json j = nlohmann::json::parse(first, nullptr, false);
  return !j.is_discarded() && j.is_object();
}

py::list errors_of(const std::string& path, const std::string& text) {
  py::list out;
  if (text.empty()) {
    out.append(utf8(path + ": error: the file is empty, not a trace; give the file `eamos run --trace FILE` wrote"));
    return out;
  }
  if (!first_line_is_object(text)) {
    out.append(utf8(path + ":1: error: not a trace: its first line is not a JSON object; give the JSON Lines "
                           "file that `eamos run --trace FILE` (or eamos.run(..., trace=FILE)) wrote"));
    return out;
  }
  std::istringstream in(text);
  std::vector<std::string> errors = trace::check_trace(in);
  for (std::size_t i = 0; i < errors.size() && i < kMaxTraceErrors; ++i) out.append(utf8(located(path, errors[i])));
  if (errors.size() > kMaxTraceErrors)
    out.append(utf8(path + ": error: " + std::to_string(errors.size() - kMaxTraceErrors) + " more problems not listed"));
  return out;
}

py::dict read_trace(const std::string& path) {
  py::dict out;
  std::string text;
  diag::FileRead r = diag::read_bounded_file(path, kMaxTraceBytes, text, diag::Pipes::read);
  if (r.status != diag::FileRead::ok) {
    py::list errors;
    errors.append(utf8(path + ": error: cannot read the trace: " + diag::describe(r, kMaxTraceBytes) +
                       "; give the file `eamos run --trace FILE` wrote"));
    out["errors"] = errors;
    return out;
  }
  py::list errors = errors_of(path, text);
  out["errors"] = errors;
  if (!errors.empty()) return out;
  std::istringstream in(text);
  py::list events;
  std::string line;
  std::getline(in, line);
  out["header"] = to_python(nlohmann::ordered_json::parse(line));
  while (std::getline(in, line)) events.append(to_python(nlohmann::ordered_json::parse(line)));
  out["events"] = events;
  return out;
}

}  // namespace

void bind_trace(py::module_& m) { m.def("read_trace", &read_trace, py::arg("path")); }

}  // namespace eamos::python
