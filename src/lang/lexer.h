#pragma once
// A hand-written lexer over one SourceFile. It never fails: bad bytes become `invalid`
// tokens after an error is reported, so the parser can go on and report more.
#include <cstddef>

#include "diag/diagnostics.h"
#include "lang/token.h"

namespace eamos::lang {

class Lexer {
 public:
  Lexer(const SourceFile& file, Diagnostics& diags) : file_(file), diags_(diags) {}

  /// The next token; returns end_of_file forever once the input is exhausted.
  Token next();

 private:
  /// Skips blanks and comments; returns true when a newline (or a comment spanning one)
  /// was crossed, which may insert a semicolon.
  void check_utf8(std::size_t begin, std::size_t end);
  void report_invalid_utf8(std::size_t at);
  bool skip_space_and_comments();
  Token make(TokenKind kind, std::size_t begin, std::size_t end);
  SourceLocation location_of(std::size_t offset);
  Token lex_number(std::size_t begin);
  Token lex_identifier(std::size_t begin);
  Token lex_operator(std::size_t begin);
  Token lex_unknown(std::size_t begin);
  bool at_end() const { return pos_ >= file_.text.size(); }
  char peek(std::size_t ahead = 0) const {
    std::size_t at = pos_ + ahead;
    return at < file_.text.size() ? file_.text[at] : '\0';
  }

  const SourceFile& file_;
  Diagnostics& diags_;
  std::size_t pos_ = 0;
  std::size_t line_ = 0;  ///< index into file_.line_starts of the last token's line
  /// Go's rule: a newline after these tokens ends the statement.
  bool semicolon_may_follow_ = false;
};

}  // namespace eamos::lang
