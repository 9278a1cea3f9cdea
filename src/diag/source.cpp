#include "diag/source.h"

#include <algorithm>

#include "diag/file_read.h"

namespace eamos {

SourceFile::SourceFile(std::string p, std::string t) : path(std::move(p)), text(std::move(t)) {
  line_starts.push_back(0);
  for (std::size_t i = 0; i < text.size(); ++i)
    if (text[i] == '\n') line_starts.push_back(i + 1);
}

std::string_view SourceFile::line(int line_number) const {
  if (line_number < 1 || static_cast<std::size_t>(line_number) > line_starts.size()) return {};
  std::size_t begin = line_starts[line_number - 1];
  std::size_t end = text.find('\n', begin);
  if (end == std::string::npos) end = text.size();
  if (end > begin && text[end - 1] == '\r') --end;
  return std::string_view(text).substr(begin, end - begin);
}

SourceLocation SourceFile::location_of(std::size_t offset) const {
  auto it = std::upper_bound(line_starts.begin(), line_starts.end(), offset);
  int line = static_cast<int>(it - line_starts.begin());
  std::size_t begin = line_starts[line - 1];
  return {line, static_cast<int>(offset - begin) + 1};
}

bool read_source_file(const std::string& path, SourceFile& out, std::string& error) {
  // Read straight into one string: a large mission is read without extra copies.
  std::string text;
  diag::FileRead r = diag::read_bounded_file(path, kMaxSourceFileBytes, text, diag::Pipes::read);
  if (r.status != diag::FileRead::ok) {
    error = diag::describe(r, kMaxSourceFileBytes);
    return false;
  }
  out = SourceFile(path, std::move(text));
  return true;
}

std::size_t utf8_sequence_length(std::string_view text, std::size_t pos) {
  auto byte = [&](std::size_t i) { return static_cast<unsigned char>(text[i]); };
  unsigned char b = byte(pos);
  if (b < 0x80) return 1;
  std::size_t n = b >= 0xC2 && b <= 0xDF ? 2 : b >= 0xE0 && b <= 0xEF ? 3 : b >= 0xF0 && b <= 0xF4 ? 4 : 0;
  if (n == 0 || pos + n > text.size()) return 0;
  for (std::size_t i = 1; i < n; ++i)
    if ((byte(pos + i) & 0xC0) != 0x80) return 0;
  unsigned char second = byte(pos + 1);
  if (b == 0xE0 && second < 0xA0) return 0;  // overlong
  if (b == 0xED && second >= 0xA0) return 0;  // a UTF-16 surrogate
  if (b == 0xF0 && second < 0x90) return 0;  // overlong
  if (b == 0xF4 && second >= 0x90) return 0;  // past U+10FFFF
  return n;
}

std::size_t first_invalid_utf8(std::string_view text, std::size_t pos, std::size_t end) {
  end = std::min(end, text.size());
  while (pos < end) {
    std::size_t n = utf8_sequence_length(text, pos);
    if (n == 0) return pos;
    pos += n;
  }
  return std::string_view::npos;
}

}  // namespace eamos
