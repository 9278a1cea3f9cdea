#pragma once
// Tokens of the mission language. The lexical rules are Go's: `//` and `/* */` comments,
// and a newline after an identifier, literal, `)` or `}` ends the statement exactly as
// a `;` does (Go's automatic semicolon insertion).
#include <string_view>

#include "diag/source.h"

namespace eamos::lang {

enum class TokenKind {
  end_of_file,
  identifier,
  integer,    ///< 42
  decimal,    ///< 4.5, 1e3
  kw_package,
  kw_var,
  kw_func,
  kw_true,
  kw_false,
  kw_async,
  lparen, rparen, lbrace, rbrace, comma, dot, semicolon,
  plus, minus, star, slash, bang,
  less, less_equal, greater, greater_equal, equal_equal, bang_equal,
  and_and, or_or,
  invalid,    ///< a byte sequence that is no token; the lexer already reported it
};

struct Token {
  TokenKind kind = TokenKind::end_of_file;
  std::string_view text;   ///< view into the SourceFile; "\n" for an inserted semicolon
  SourceLocation loc;
};

const char* token_kind_name(TokenKind kind);

}  // namespace eamos::lang
