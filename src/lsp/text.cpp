#include "lsp/text.h"

#include <algorithm>
#include <cctype>

namespace eamos::lsp {

nlohmann::json to_json(const Position& p) { return {{"line", p.line}, {"character", p.character}}; }
nlohmann::json to_json(const Range& r) { return {{"start", to_json(r.start)}, {"end", to_json(r.end)}}; }

namespace {

// Bytes of the UTF-8 sequence a lead byte starts; a stray byte counts as one.
std::size_t sequence_length(unsigned char lead) {
  if (lead >= 0xF0 && lead < 0xF8) return 4;
  if (lead >= 0xE0) return lead < 0xF0 ? 3 : 1;
  if (lead >= 0xC0) return 2;
  return 1;
}

// UTF-16 code units of one sequence: a character beyond the BMP is a surrogate pair.
int utf16_units(std::size_t sequence) { return sequence == 4 ? 2 : 1; }

bool word_char(unsigned char c) { return std::isalnum(c) || c == '_'; }

}  // namespace

int units_in(std::string_view line, std::size_t bytes, Encoding enc) {
  if (bytes > line.size()) bytes = line.size();
  if (enc == Encoding::utf8) return static_cast<int>(bytes);
  int units = 0;
  for (std::size_t i = 0; i < bytes;) {
    std::size_t n = sequence_length(static_cast<unsigned char>(line[i]));
    units += utf16_units(n);
    i += n;
  }
  return units;
}

std::size_t bytes_for(std::string_view line, int units, Encoding enc) {
  if (units <= 0) return 0;
  if (enc == Encoding::utf8) return std::min(line.size(), static_cast<std::size_t>(units));
  std::size_t i = 0;
  int seen = 0;
  while (i < line.size() && seen < units) {
    std::size_t n = sequence_length(static_cast<unsigned char>(line[i]));
    seen += utf16_units(n);
    i = std::min(line.size(), i + n);
  }
  return i;
}

Position to_position(std::string_view line, SourceLocation loc, Encoding enc) {
  if (!loc.known()) return {};
  std::size_t bytes = loc.col > 1 ? static_cast<std::size_t>(loc.col - 1) : 0;
  return {loc.line - 1, units_in(line, bytes, enc)};
}

Range word_range(std::string_view line, SourceLocation loc, Encoding enc) {
  Position start = to_position(line, loc, enc);
  if (!loc.known()) return {start, start};
  std::size_t begin = loc.col > 1 ? static_cast<std::size_t>(loc.col - 1) : 0;
  if (begin >= line.size()) return {start, start};
  std::size_t end = begin;
  auto at = [&](std::size_t i) { return static_cast<unsigned char>(line[i]); };
  if (word_char(at(begin))) {
    while (end < line.size() && (word_char(at(end)) || (std::isdigit(at(begin)) && at(end) == '.'))) ++end;
  } else {
    static const char* pairs[] = {"<=", ">=", "==", "!=", "&&", "||"};
    std::string_view two = line.substr(begin, 2);
    end = begin + sequence_length(at(begin));
    for (const char* p : pairs)
      if (two == p) end = begin + 2;
    end = std::min(end, line.size());
  }
  return {start, {start.line, units_in(line, end, enc)}};
}

namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

std::string uri_to_path(const std::string& uri) {
  const std::string scheme = "file://";
  if (uri.compare(0, scheme.size(), scheme) != 0) return "";
  std::string rest = uri.substr(scheme.size());
  // file:///p and file://localhost/p name a local file; another host does not.
  std::size_t slash = rest.find('/');
  if (slash == std::string::npos) return "";
  std::string host = rest.substr(0, slash);
  if (!host.empty() && host != "localhost") return "";
  std::string path;
  for (std::size_t i = slash; i < rest.size(); ++i) {
    if (rest[i] == '%' && i + 2 < rest.size() && hex_value(rest[i + 1]) >= 0 && hex_value(rest[i + 2]) >= 0) {
      path += static_cast<char>(hex_value(rest[i + 1]) * 16 + hex_value(rest[i + 2]));
      i += 2;
    } else {
      path += rest[i];
    }
  }
  if (path.find('\0') != std::string::npos) return "";
  return path;
}

std::string path_to_uri(const std::string& path) {
  static const char* hex = "0123456789ABCDEF";
  std::string uri = "file://";
  for (unsigned char c : path) {
    if (std::isalnum(c) || c == '/' || c == '-' || c == '.' || c == '_' || c == '~') {
      uri += static_cast<char>(c);
    } else {
      uri += '%';
      uri += hex[c >> 4];
      uri += hex[c & 15];
    }
  }
  return uri;
}

}  // namespace eamos::lsp
