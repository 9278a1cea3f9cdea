#pragma once
// Errors and warnings as values. Every stage appends to one Diagnostics list instead of
// stopping at the first problem, so a single run reports everything wrong with a file.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "diag/source.h"

namespace eamos {

enum class Severity { error, warning, note };
/// "error", "warning" or "note": the word every format prints (text, JSON, SARIF, Python).
const char* severity_name(Severity s);

/// A diagnostic owns the text it prints (the file's path and the one source line it points
/// at) instead of pointing into the SourceFile: a fleet or mission source is often gone by
/// the time the CLI prints, and a diagnostic must never be able to outlive what it shows.
struct Diagnostic {
  Severity severity = Severity::error;
  bool has_file = false;    ///< false: not tied to a file (e.g. a CLI problem)
  std::string path;         ///< the file as the user named it
  SourceLocation loc;
  std::string source_line;  ///< the text of line loc.line, copied when reported
  std::string message;      ///< "what; how to fix" — no trailing newline
  /// Bytes of source_line underlined from loc.col (`^~~~`): the range the front end gave, or
  /// the token at the column; 0 for the caret alone (a position between tokens, past the end).
  int length = 0;
  /// A note that belongs to the diagnostic before it in the list ("first defined here"): it is
  /// printed right under that one, wherever its own location is, and dropped with it.
  bool attached = false;
};

/// How Diagnostics::format prints: colour (ANSI escapes, as clang and GCC on a terminal).
struct FormatOptions {
  bool color = false;
};

class Diagnostics {
 public:
  /// After this many errors further ones are counted but not kept; 0 keeps all.
  std::size_t max_errors = 200;

  /// `length`: bytes underlined from loc.col when the caller knows the range; 0 underlines
  /// the token at loc.col.
  void error(const SourceFile* file, SourceLocation loc, std::string message, int length = 0);
  void warning(const SourceFile* file, SourceLocation loc, std::string message, int length = 0);
  /// A note right after an error or warning belongs to it (printed under it, with its own
  /// location); one reported first stands alone.
  void note(const SourceFile* file, SourceLocation loc, std::string message, int length = 0);

  bool has_errors() const { return error_count_ > 0; }
  std::size_t error_count() const { return error_count_; }
  std::size_t warning_count() const { return warning_count_; }
  /// True once max_errors is reached: stages may stop early to bound the work on garbage.
  bool saturated() const { return max_errors != 0 && error_count_ >= max_errors; }
  const std::vector<Diagnostic>& items() const { return items_; }
  /// Adds an already-made diagnostic (e.g. one re-listed from another run's list).
  void add(Diagnostic d);

  /// GCC-style text: `file:line:col: error: message`, then the source line and a caret,
  /// ordered by file position; ends with a count line when anything was dropped.
  std::string format(FormatOptions options = {}) const;
  /// Errors past max_errors that were counted but not kept.
  std::size_t dropped() const { return dropped_; }

 private:
  void add(Severity severity, const SourceFile* file, SourceLocation loc, std::string message, int length);
  bool count(Severity severity);
  bool last_kept_ = false;  ///< whether the last error or warning was kept (its notes follow it)
  std::vector<Diagnostic> items_;
  std::size_t error_count_ = 0;
  std::size_t warning_count_ = 0;
  std::size_t dropped_ = 0;
};

/// "1 error", "2 errors": a count and its noun, plural by English's plain -s rule.
std::string count_of(std::size_t n, const std::string& noun);

/// The closest candidate by edit distance, or "" when none is close enough to suggest.
std::string closest_match(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace eamos
