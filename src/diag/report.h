#pragma once
// Diagnostics for tools: JSON (one object per diagnostic, its notes inside it) and SARIF 2.1.0
// (the OASIS format code-scanning services and IDEs read). The text form is Diagnostics::format.
#include <string>

#include "diag/diagnostics.h"

namespace eamos {

/// {"diagnostics": [{"file", "line", "column", "end_column", "severity", "message",
/// "source_line", "notes": [...]}], "errors": N, "warnings": N, "not_shown": N}; columns are
/// 1-based bytes as in the text form, end_column exclusive; a diagnostic without a file has
/// "file": null, one without a position line and column 0.
std::string diagnostics_json(const Diagnostics& diags);

/// A SARIF 2.1.0 log with one run of `tool` at `version`: each error and warning (and each
/// standalone note) a result, its notes relatedLocations. Columns count Unicode code points
/// (run.columnKind "unicodeCodePoints"); relative paths are relative to %SRCROOT%, the
/// working directory given.
std::string diagnostics_sarif(const Diagnostics& diags, const std::string& tool, const std::string& version,
                              const std::string& working_dir);

}  // namespace eamos
