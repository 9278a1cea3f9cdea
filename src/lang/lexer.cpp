#include "lang/lexer.h"

#include <array>
#include <string>

namespace eamos::lang {

const char* token_kind_name(TokenKind kind) {
  switch (kind) {
    case TokenKind::end_of_file: return "end of file";
    case TokenKind::identifier: return "identifier";
    case TokenKind::integer: return "integer";
    case TokenKind::decimal: return "number";
    case TokenKind::kw_package: return "'package'";
    case TokenKind::kw_var: return "'var'";
    case TokenKind::kw_func: return "'func'";
    case TokenKind::kw_true: return "'true'";
    case TokenKind::kw_false: return "'false'";
    case TokenKind::kw_async: return "'async'";
    case TokenKind::lparen: return "'('";
    case TokenKind::rparen: return "')'";
    case TokenKind::lbrace: return "'{'";
    case TokenKind::rbrace: return "'}'";
    case TokenKind::comma: return "','";
    case TokenKind::dot: return "'.'";
    case TokenKind::semicolon: return "';' or newline";
    case TokenKind::plus: return "'+'";
    case TokenKind::minus: return "'-'";
    case TokenKind::star: return "'*'";
    case TokenKind::slash: return "'/'";
    case TokenKind::bang: return "'!'";
    case TokenKind::less: return "'<'";
    case TokenKind::less_equal: return "'<='";
    case TokenKind::greater: return "'>'";
    case TokenKind::greater_equal: return "'>='";
    case TokenKind::equal_equal: return "'=='";
    case TokenKind::bang_equal: return "'!='";
    case TokenKind::and_and: return "'&&'";
    case TokenKind::or_or: return "'||'";
    case TokenKind::invalid: return "invalid token";
  }
  return "token";
}

namespace {

// The character classes of the ASCII the language is written in, by table: <cctype>'s
// functions are calls into the C library per byte (and follow the locale), a tenth of
// the parse of a large mission.
enum : unsigned char { kDigit = 1, kLetter = 2, kSpace = 4 };
constexpr auto kClass = [] {
  std::array<unsigned char, 256> t{};
  for (int c = '0'; c <= '9'; ++c) t[c] = kDigit;
  for (int c = 'a'; c <= 'z'; ++c) t[c] = kLetter;
  for (int c = 'A'; c <= 'Z'; ++c) t[c] = kLetter;
  for (char c : {' ', '\t', '\n', '\v', '\f', '\r'}) t[static_cast<unsigned char>(c)] = kSpace;
  return t;
}();
bool is_digit(char c) { return kClass[static_cast<unsigned char>(c)] & kDigit; }
bool is_letter(char c) { return kClass[static_cast<unsigned char>(c)] & kLetter; }
bool is_word(char c) { return (kClass[static_cast<unsigned char>(c)] & (kDigit | kLetter)) || c == '_'; }
bool is_space(char c) { return kClass[static_cast<unsigned char>(c)] & kSpace; }

}  // namespace

Token Lexer::make(TokenKind kind, std::size_t begin, std::size_t end) {
  return {kind, std::string_view(file_.text).substr(begin, end - begin), location_of(begin)};
}

// Tokens come in order, so the line of the previous token is where to start looking; a
// search over all lines per token was a tenth of the parse.
SourceLocation Lexer::location_of(std::size_t offset) {
  const std::vector<std::size_t>& starts = file_.line_starts;
  if (starts.empty() || offset < starts[line_]) return file_.location_of(offset);
  while (line_ + 1 < starts.size() && starts[line_ + 1] <= offset) ++line_;
  return {static_cast<int>(line_) + 1, static_cast<int>(offset - starts[line_]) + 1};
}

void Lexer::report_invalid_utf8(std::size_t at) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02x", static_cast<unsigned char>(file_.text[at]));
  diags_.error(&file_, file_.location_of(at),
               std::string("invalid UTF-8: byte ") + buf +
                   " does not begin or continue a UTF-8 character; save the file as UTF-8 or remove the byte");
}

// One error per comment: a comment in another encoding (Latin-1) has many such bytes.
void Lexer::check_utf8(std::size_t begin, std::size_t end) {
  std::size_t bad = first_invalid_utf8(file_.text, begin, end);
  if (bad != std::string_view::npos) report_invalid_utf8(bad);
}

bool Lexer::skip_space_and_comments() {
  bool crossed_newline = false;
  while (!at_end()) {
    char c = peek();
    if (c == '\n') {
      crossed_newline = true;
      ++pos_;
    } else if (c == ' ' || c == '\t' || c == '\r') {
      ++pos_;
    } else if (c == '/' && peek(1) == '/') {
      std::size_t begin = pos_;
      while (!at_end() && peek() != '\n') ++pos_;
      check_utf8(begin, pos_);
    } else if (c == '/' && peek(1) == '*') {
      std::size_t begin = pos_;
      std::size_t close = file_.text.find("*/", pos_ + 2);
      std::size_t stop = close == std::string::npos ? file_.text.size() : close + 2;
      if (file_.text.find('\n', pos_) < stop) crossed_newline = true;
      if (close == std::string::npos)
        diags_.error(&file_, file_.location_of(begin),
                     "comment not terminated; close it with '*/'");
      check_utf8(begin, stop);
      pos_ = stop;
    } else {
      break;
    }
  }
  return crossed_newline;
}

Token Lexer::next() {
  std::size_t before = pos_;
  bool newline = skip_space_and_comments();
  if (semicolon_may_follow_ && (newline || at_end())) {
    semicolon_may_follow_ = false;
    // The inserted semicolon sits where the line ended, so errors point at that line.
    std::size_t at = before;
    Token t = make(TokenKind::semicolon, at, at);
    t.text = "\n";
    return t;
  }
  if (at_end()) {
    semicolon_may_follow_ = false;
    return make(TokenKind::end_of_file, pos_, pos_);
  }
  std::size_t begin = pos_;
  unsigned char c = static_cast<unsigned char>(peek());
  Token t;
  if (is_digit(static_cast<char>(c)) || (c == '.' && is_digit(peek(1))))
    t = lex_number(begin);
  else if (is_letter(static_cast<char>(c)) || c == '_')
    t = lex_identifier(begin);
  else
    t = lex_operator(begin);
  semicolon_may_follow_ = t.kind == TokenKind::identifier || t.kind == TokenKind::integer ||
                          t.kind == TokenKind::decimal || t.kind == TokenKind::kw_true ||
                          t.kind == TokenKind::kw_false || t.kind == TokenKind::rparen ||
                          t.kind == TokenKind::rbrace;
  return t;
}

Token Lexer::lex_number(std::size_t begin) {
  auto digit = [&] { return is_digit(peek()); };
  bool is_decimal = false;
  while (digit()) ++pos_;
  if (peek() == '.' && is_digit(peek(1))) {
    is_decimal = true;
    ++pos_;
    while (digit()) ++pos_;
  } else if (peek() == '.' && !is_letter(peek(1)) && peek(1) != '_') {
    // "5." is a decimal in Go; "Drone1.X" never starts with a digit, so no ambiguity.
    is_decimal = true;
    ++pos_;
  }
  if (peek() == 'e' || peek() == 'E') {
    std::size_t save = pos_;
    ++pos_;
    if (peek() == '+' || peek() == '-') ++pos_;
    if (digit()) {
      is_decimal = true;
      while (digit()) ++pos_;
    } else {
      pos_ = save;
    }
  }
  if (is_letter(peek()) || peek() == '_') {
    while (is_word(peek())) ++pos_;
    diags_.error(&file_, file_.location_of(begin),
                 "malformed number '" + std::string(file_.text.substr(begin, pos_ - begin)) +
                     "'; a number cannot be followed by letters (units are implied: metres, seconds)");
    return make(TokenKind::invalid, begin, pos_);
  }
  return make(is_decimal ? TokenKind::decimal : TokenKind::integer, begin, pos_);
}

Token Lexer::lex_identifier(std::size_t begin) {
  while (is_word(peek())) ++pos_;
  Token t = make(TokenKind::identifier, begin, pos_);
  if (t.text == "package") t.kind = TokenKind::kw_package;
  else if (t.text == "var") t.kind = TokenKind::kw_var;
  else if (t.text == "func") t.kind = TokenKind::kw_func;
  else if (t.text == "true") t.kind = TokenKind::kw_true;
  else if (t.text == "false") t.kind = TokenKind::kw_false;
  else if (t.text == "async") t.kind = TokenKind::kw_async;
  return t;
}

Token Lexer::lex_operator(std::size_t begin) {
  char c = peek();
  char n = peek(1);
  auto two = [&](TokenKind k) { pos_ += 2; return make(k, begin, pos_); };
  auto one = [&](TokenKind k) { pos_ += 1; return make(k, begin, pos_); };
  switch (c) {
    case '(': return one(TokenKind::lparen);
    case ')': return one(TokenKind::rparen);
    case '{': return one(TokenKind::lbrace);
    case '}': return one(TokenKind::rbrace);
    case ',': return one(TokenKind::comma);
    case '.': return one(TokenKind::dot);
    case ';': return one(TokenKind::semicolon);
    case '+': return one(TokenKind::plus);
    case '-': return one(TokenKind::minus);
    case '*': return one(TokenKind::star);
    case '/': return one(TokenKind::slash);
    case '!': return n == '=' ? two(TokenKind::bang_equal) : one(TokenKind::bang);
    case '<': return n == '=' ? two(TokenKind::less_equal) : one(TokenKind::less);
    case '>': return n == '=' ? two(TokenKind::greater_equal) : one(TokenKind::greater);
    case '=':
      if (n == '=') return two(TokenKind::equal_equal);
      break;
    case '&':
      if (n == '&') return two(TokenKind::and_and);
      break;
    case '|':
      if (n == '|') return two(TokenKind::or_or);
      break;
    default: break;
  }
  return lex_unknown(begin);
}

// Swallows a whole run of unknown bytes as one token: binary garbage gives one error per run,
// not one per byte.
Token Lexer::lex_unknown(std::size_t begin) {
  char c = peek();
  while (!at_end()) {
    unsigned char u = static_cast<unsigned char>(peek());
    bool known = is_word(static_cast<char>(u)) || is_space(static_cast<char>(u)) || std::string_view("(){},.;+-*/!<>_\"").find(char(u)) != std::string_view::npos;
    if (known && pos_ > begin) break;
    ++pos_;
    if (known) break;
  }
  std::string shown;
  unsigned char first = static_cast<unsigned char>(c);
  std::string fix = "; remove it";
  if (c == '=') { shown = "'='"; fix = "; the language has no assignment, write '==' to compare"; }
  else if (c == '&' || c == '|') { shown = std::string("'") + c + "'"; fix = std::string("; write '") + c + c + "'"; }
  else if (c == '"') { shown = "'\"'"; fix = "; the language has no strings"; }
  else if (first >= 0x21 && first < 0x7f) shown = std::string("'") + c + "'";
  else {
    char buf[8];
    std::snprintf(buf, sizeof buf, "0x%02x", first);
    shown = std::string("byte ") + buf;
    if (first >= 0x80) fix = "; only ASCII is allowed outside comments (a typographic dash or quote?)";
  }
  std::size_t bad = first_invalid_utf8(file_.text, begin, pos_);
  if (bad != std::string_view::npos) {
    report_invalid_utf8(bad);
    return make(TokenKind::invalid, begin, pos_);
  }
  diags_.error(&file_, file_.location_of(begin), "unexpected " + shown + fix);
  return make(TokenKind::invalid, begin, pos_);
}

}  // namespace eamos::lang
