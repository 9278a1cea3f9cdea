#pragma once
// A streaming JSON writer: values go straight to an output stream, so a large mission file
// is never held in memory as a document tree. Values print the way nlohmann::json prints
// them (strings escaped the same way, doubles in their shortest form that reads back to the
// same value, integral doubles with ".0"), so a file written here parses to exactly the
// nlohmann::json the graph exporters build.
#include <cstring>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace eamos::deploy {

class JsonWriter {
 public:
  /// Members and elements of containers nested less than `wrap_depth` deep start on a line
  /// of their own, indented one space per level; deeper ones stay on their parent's line.
  /// 0 writes the whole document on one line: the canonical form the mission hash reads.
  explicit JsonWriter(std::ostream& out, int wrap_depth = 0);
  /// Appends to `text` instead, all of it, with no stream between: a mission file is
  /// made whole in one buffer, hashed there and written with one call.
  explicit JsonWriter(std::string& text, int wrap_depth = 0);
  ~JsonWriter();  ///< flushes

  void begin_object();
  void end_object();
  void begin_array();
  void end_array();
  /// The name of the next object member; its value follows with value() or begin_*().
  void key(std::string_view name);
  /// A name written as a literal in the writer's caller: plain ASCII, so copied without the
  /// scan for bytes to escape (a large fleet's files hold tens of millions of names).
  template <std::size_t N>
  void key(const char (&name)[N]) {
    key_plain(std::string_view(name, N - 1));
  }

  void value(std::string_view s);
  void value(const char* s);  ///< so that a string literal is not taken for a bool
  void value(double v);       ///< NaN and infinities are written as null, as nlohmann does
  void value(int v);
  void value(long long v);
  void value(bool v);
  void null();

  /// key() then value(), for the common one-line member.
  template <std::size_t N, typename Value>
  void member(const char (&name)[N], const Value& v) {
    key(name);
    value(v);
  }
  void member(std::string_view name, std::string_view s) { key(name); value(s); }
  void member(std::string_view name, const char* s) { key(name); value(s); }
  void member(std::string_view name, double v) { key(name); value(v); }
  void member(std::string_view name, int v) { key(name); value(v); }
  void member(std::string_view name, long long v) { key(name); value(v); }
  void member(std::string_view name, bool v) { key(name); value(v); }

  /// Hands what is buffered to the stream; false when the stream has failed. Appending
  /// to a string, it has nothing to do.
  bool flush();

 private:
  void begin_value();  ///< separator and line break before a member or an element
  void key_plain(std::string_view name);
  void open(char bracket);
  void close(char bracket);
  void write_string(std::string_view s);
  void write_escaped(std::string_view s);  ///< any string, escaped as nlohmann::json does
  void line_break(std::size_t depth);

  /// Room for `n` more bytes at cur_. Bytes are written through a pointer into space the
  /// string already holds, not appended one by one: each append checks and sets the
  /// string's length, and a large fleet's files are written a few bytes at a time.
  void reserve(std::size_t n) {
    if (static_cast<std::size_t>(end_ - cur_) < n) grow(n);
  }
  void grow(std::size_t n);
  void put(char c) {
    reserve(1);
    *cur_++ = c;
  }
  void put(std::string_view s) {
    reserve(s.size());
    std::memcpy(cur_, s.data(), s.size());
    cur_ += s.size();
  }
  /// Bytes that need no escape, in quotes.
  void put_quoted(std::string_view plain) {
    reserve(plain.size() + 2);
    *cur_++ = '"';
    std::memcpy(cur_, plain.data(), plain.size());
    cur_ += plain.size();
    *cur_++ = '"';
  }
  /// Gives the string the length of what is written (it holds spare room while writing).
  void settle();

  std::ostream* out_ = nullptr;  ///< null: the text appended to is the whole output
  std::string own_;              ///< the buffer when writing to a stream
  std::string& buffer_;          ///< written to out_ in large pieces
  char* cur_ = nullptr;          ///< where the next byte goes, inside buffer_
  char* end_ = nullptr;          ///< the end of buffer_'s room
  int wrap_depth_;
  std::vector<char> has_items_;  ///< per open container: 1 once something is in it
  bool after_key_ = false;       ///< a key was written; the next value is its member's
};

}  // namespace eamos::deploy
