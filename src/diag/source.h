#pragma once
// A loaded text file (mission or fleet) and positions in it. Every later stage points
// back here, so a node in any graph can name the line and column that produced it.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace eamos {

/// 1-based line and byte column; {0, 0} means "no position" (e.g. a generated node).
struct SourceLocation {
  int line = 0;
  int col = 0;
  bool known() const { return line > 0; }
};

struct SourceFile {
  std::string path;  ///< as given by the user; printed in diagnostics
  std::string text;  ///< whole content, raw bytes (may be binary garbage)
  std::vector<std::size_t> line_starts;  ///< byte offset of each line's first byte

  SourceFile() = default;
  SourceFile(std::string path, std::string text);

  /// The text of a 1-based line without its newline; empty when out of range.
  std::string_view line(int line_number) const;
  /// Line and column of a byte offset.
  SourceLocation location_of(std::size_t offset) const;
};

/// Bytes of the UTF-8 sequence that starts at `pos` (1 for ASCII); 0 when the bytes there
/// are not valid UTF-8: a stray continuation byte, a truncated or overlong sequence, a
/// surrogate, a code point past U+10FFFF.
std::size_t utf8_sequence_length(std::string_view text, std::size_t pos);
/// Offset of the first byte in [pos, end) that is not valid UTF-8, or std::string_view::npos.
std::size_t first_invalid_utf8(std::string_view text, std::size_t pos, std::size_t end);

/// The most a mission or fleet file may hold: 256 MiB, some 3.7 million statements, far more
/// than a compile fits in memory; a device such as /dev/zero stops here at the latest.
constexpr std::size_t kMaxSourceFileBytes = std::size_t{256} << 20;

/// Reads a whole regular file, or a pipe to its end (/dev/stdin, <(...)), of at most
/// kMaxSourceFileBytes; returns false and sets `error` (the system's reason, or what is wrong
/// with the file: "a character device, not a regular file") otherwise.
bool read_source_file(const std::string& path, SourceFile& out, std::string& error);

}  // namespace eamos
