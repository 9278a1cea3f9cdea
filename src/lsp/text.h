#pragma once
// Positions and names as the protocol writes them. The compiler counts 1-based lines and
// byte columns; LSP counts 0-based lines and, unless the client agrees to UTF-8, UTF-16
// code units. Documents are named by URI; the compiler's diagnostics by path.
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "diag/source.h"

namespace eamos::lsp {

enum class Encoding { utf16, utf8 };

struct Position {
  int line = 0;       ///< 0-based
  int character = 0;  ///< 0-based, in code units of the session's encoding
};

struct Range {
  Position start;
  Position end;
};

nlohmann::json to_json(const Position& p);
nlohmann::json to_json(const Range& r);

/// Code units of `enc` in the first `bytes` bytes of `line`.
int units_in(std::string_view line, std::size_t bytes, Encoding enc);
/// The byte offset in `line` where code unit `units` starts (the line's length beyond it).
std::size_t bytes_for(std::string_view line, int units, Encoding enc);

/// A compiler location (1-based line, byte column) on the line whose text is `line`.
Position to_position(std::string_view line, SourceLocation loc, Encoding enc);
/// The range of the word a diagnostic points at: an identifier, a number, a two-character
/// operator, else one character (nothing past the line's end).
Range word_range(std::string_view line, SourceLocation loc, Encoding enc);

/// The file a `file:` URI names (percent-decoded); "" for any other URI.
std::string uri_to_path(const std::string& uri);
/// The `file:` URI of an absolute path.
std::string path_to_uri(const std::string& path);

}  // namespace eamos::lsp
