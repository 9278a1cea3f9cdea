#include "deploy/json_writer.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <charconv>
#include <cmath>

namespace eamos::deploy {

namespace {

/// Buffered output reaches the stream in pieces of about this size.
constexpr std::size_t kFlushAt = 64 * 1024;

/// The bytes a JSON string holds as they are: printable ASCII but the quote and backslash.
constexpr auto kPlain = [] {
  std::array<bool, 256> plain{};
  for (int c = 0x20; c < 0x80; ++c) plain[c] = c != '"' && c != '\\';
  return plain;
}();

/// Length of the well-formed UTF-8 sequence at the start of `s` (1 to 4), or 0 when the
/// bytes there are not one (a stray continuation byte, an overlong form, a surrogate, a
/// code point above U+10FFFF, or a sequence cut short).
std::size_t utf8_length(std::string_view s) {
  auto byte = [&](std::size_t i) { return static_cast<unsigned char>(s[i]); };
  unsigned char b = byte(0);
  std::size_t length = 0;
  unsigned char low = 0x80, high = 0xBF;  // allowed range of the second byte
  if (b < 0x80) return 1;
  if (b >= 0xC2 && b <= 0xDF) length = 2;
  else if (b >= 0xE0 && b <= 0xEF) length = 3;
  else if (b >= 0xF0 && b <= 0xF4) length = 4;
  else return 0;
  if (b == 0xE0) low = 0xA0;   // overlong
  if (b == 0xED) high = 0x9F;  // UTF-16 surrogates
  if (b == 0xF0) low = 0x90;   // overlong
  if (b == 0xF4) high = 0x8F;  // above U+10FFFF
  if (s.size() < length) return 0;
  if (byte(1) < low || byte(1) > high) return 0;
  for (std::size_t i = 2; i < length; ++i)
    if (byte(i) < 0x80 || byte(i) > 0xBF) return 0;
  return length;
}

}  // namespace

JsonWriter::JsonWriter(std::ostream& out, int wrap_depth) : out_(&out), buffer_(own_), wrap_depth_(wrap_depth) {
  grow(kFlushAt + 1024);
}

JsonWriter::JsonWriter(std::string& text, int wrap_depth) : buffer_(text), wrap_depth_(wrap_depth) {
  cur_ = end_ = buffer_.data() + buffer_.size();
}

JsonWriter::~JsonWriter() { flush(); }

void JsonWriter::grow(std::size_t n) {
  std::size_t used = cur_ ? static_cast<std::size_t>(cur_ - buffer_.data()) : buffer_.size();
  // All the room already allocated, else double: a text written in small pieces is copied
  // a bounded number of times, and a reused string is not allocated again.
  buffer_.resize(std::max({buffer_.capacity(), buffer_.size() * 2, used + n, std::size_t{4096}}));
  cur_ = buffer_.data() + used;
  end_ = buffer_.data() + buffer_.size();
}

void JsonWriter::settle() {
  buffer_.resize(static_cast<std::size_t>(cur_ - buffer_.data()));
  cur_ = end_ = buffer_.data() + buffer_.size();
}

bool JsonWriter::flush() {
  settle();
  if (!out_) return true;
  out_->write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  buffer_.clear();
  cur_ = end_ = buffer_.data();
  grow(0);
  return static_cast<bool>(*out_);
}

void JsonWriter::line_break(std::size_t depth) {
  reserve(depth + 1);
  *cur_++ = '\n';
  std::memset(cur_, ' ', depth);
  cur_ += depth;
}

void JsonWriter::begin_value() {
  if (out_ && static_cast<std::size_t>(cur_ - buffer_.data()) >= kFlushAt) flush();
  if (after_key_) {
    after_key_ = false;
    return;
  }
  if (has_items_.empty()) return;  // the document's top-level value
  if (has_items_.back()) put(',');
  has_items_.back() = 1;
  if (has_items_.size() <= static_cast<std::size_t>(wrap_depth_)) line_break(has_items_.size());
}

void JsonWriter::open(char bracket) {
  begin_value();
  put(bracket);
  has_items_.push_back(0);
}

void JsonWriter::close(char bracket) {
  bool had_items = has_items_.back();
  has_items_.pop_back();
  if (had_items && has_items_.size() < static_cast<std::size_t>(wrap_depth_))
    line_break(has_items_.size());
  put(bracket);
}

void JsonWriter::begin_object() { open('{'); }
void JsonWriter::end_object() { close('}'); }
void JsonWriter::begin_array() { open('['); }
void JsonWriter::end_array() { close(']'); }

void JsonWriter::key(std::string_view name) {
  begin_value();
  write_string(name);
  put(':');
  after_key_ = true;
}

void JsonWriter::key_plain(std::string_view name) {
  begin_value();
  put_quoted(name);
  put(':');
  after_key_ = true;
}

void JsonWriter::value(std::string_view s) {
  begin_value();
  write_string(s);
}

void JsonWriter::value(const char* s) { value(std::string_view(s)); }

void JsonWriter::value(double v) {
  if (!std::isfinite(v)) {
    null();
    return;
  }
  begin_value();
  char text[64];
  // Without a format, to_chars writes the shortest text that reads back to exactly v.
  auto [end, ec] = std::to_chars(text, text + sizeof text, v);
  (void)ec;  // 64 characters always suffice for a double
  std::string_view written(text, static_cast<std::size_t>(end - text));
  put(written);
  // nlohmann::json marks integral doubles with ".0" so they read back as floating point.
  if (written.find_first_of(".e") == std::string_view::npos) put(".0");
}

void JsonWriter::value(int v) { value(static_cast<long long>(v)); }

void JsonWriter::value(long long v) {
  begin_value();
  char text[24];
  auto [end, ec] = std::to_chars(text, text + sizeof text, v);
  (void)ec;
  put(std::string_view(text, static_cast<std::size_t>(end - text)));
}

void JsonWriter::value(bool v) {
  begin_value();
  put(v ? "true" : "false");
}

void JsonWriter::null() {
  begin_value();
  put("null");
}

void JsonWriter::write_string(std::string_view s) {
  // Most strings are short names with nothing to escape (a drone's, a capability's): one
  // look at their bytes, then one copy with the quotes.
  if (s.size() <= 64 && std::all_of(s.begin(), s.end(), [](char c) { return kPlain[static_cast<unsigned char>(c)]; }))
    put_quoted(s);
  else
    write_escaped(s);
}

// The escapes nlohmann::json writes (without ensure_ascii): quote, backslash and control
// characters; other UTF-8 passes through. Bytes that are not UTF-8 become U+FFFD, so the
// output is always valid JSON whatever a fleet file or path contained. Runs of bytes that
// need nothing are copied in one piece.
void JsonWriter::write_escaped(std::string_view s) {
  static const char* hex = "0123456789abcdef";
  put('"');
  std::size_t copied = 0;  // s[0, copied) is in the buffer
  std::size_t i = 0;
  auto hand_over = [&] {  // to the stream, in pieces: a 35 MB source is never whole in memory
    if (out_ && static_cast<std::size_t>(cur_ - buffer_.data()) >= kFlushAt) flush();
  };
  while (i < s.size()) {
    // Names, keys and labels are plain ASCII: one table look-up per byte finds the end of
    // such a run.
    std::size_t stop = std::min(s.size(), copied + kFlushAt);
    while (i < stop && kPlain[static_cast<unsigned char>(s[i])]) ++i;
    if (i >= stop) {
      put(s.substr(copied, i - copied));
      copied = i;
      hand_over();
      continue;
    }
    unsigned char c = static_cast<unsigned char>(s[i]);
    if (c >= 0x80) {
      std::size_t n = utf8_length(s.substr(i));
      if (n > 0) {
        i += n;
        continue;
      }
    }
    put(s.substr(copied, i - copied));
    switch (c) {
      case '"': put("\\\""); break;
      case '\\': put("\\\\"); break;
      case '\b': put("\\b"); break;
      case '\f': put("\\f"); break;
      case '\n': put("\\n"); break;
      case '\r': put("\\r"); break;
      case '\t': put("\\t"); break;
      default:
        if (c >= 0x80) {
          put("\xEF\xBF\xBD");  // not UTF-8: U+FFFD
        } else {
          put("\\u00");
          put(hex[c >> 4]);
          put(hex[c & 15]);
        }
    }
    ++i;
    copied = i;
    hand_over();
  }
  put(s.substr(copied));
  put('"');
}

}  // namespace eamos::deploy
