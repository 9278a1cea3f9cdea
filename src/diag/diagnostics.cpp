#include "diag/diagnostics.h"

#include <algorithm>
#include <cctype>
#include <cstdio>

namespace eamos {

void Diagnostics::error(const SourceFile* file, SourceLocation loc, std::string message, int length) {
  add(Severity::error, file, loc, std::move(message), length);
}
void Diagnostics::warning(const SourceFile* file, SourceLocation loc, std::string message, int length) {
  add(Severity::warning, file, loc, std::move(message), length);
}
void Diagnostics::note(const SourceFile* file, SourceLocation loc, std::string message, int length) {
  add(Severity::note, file, loc, std::move(message), length);
}

// Counts the diagnostic and says whether to keep it (errors past max_errors are dropped,
// and with them the notes that follow them).
bool Diagnostics::count(Severity severity) {
  if (severity == Severity::note) return items_.empty() || last_kept_;
  bool keep = true;
  if (severity == Severity::error) {
    ++error_count_;
    if (max_errors != 0 && error_count_ > max_errors) {
      ++dropped_;
      keep = false;
    }
  } else {
    ++warning_count_;
  }
  last_kept_ = keep;
  return keep;
}

namespace {

bool word_byte(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// The token at a 1-based column, as mission and fleet files spell them: a name or number, a
// quoted string, a run of operator characters, else one character; 0 on blanks and past the
// end, where only a caret makes sense.
int token_length(std::string_view line, int col) {
  if (col < 1 || static_cast<std::size_t>(col) > line.size()) return 0;
  std::size_t i = col - 1, j = i;
  char c = line[i];
  if (c == ' ' || c == '\t') return 0;
  if (word_byte(c)) {
    bool number = std::isdigit(static_cast<unsigned char>(c));
    while (j < line.size() && (word_byte(line[j]) || (number && line[j] == '.'))) ++j;
  } else if (c == '"' || c == '\'') {
    j = line.find(c, i + 1);
    j = j == std::string_view::npos ? line.size() : j + 1;
  } else if (std::string_view("<>=!&|+-*/%").find(c) != std::string_view::npos) {
    while (j < line.size() && j < i + 2 && std::string_view("<>=!&|").find(line[j]) != std::string_view::npos) ++j;
    if (j == i) ++j;
  } else {
    j = i + 1;
  }
  return static_cast<int>(j - i);
}

}  // namespace

void Diagnostics::add(Severity severity, const SourceFile* file, SourceLocation loc, std::string message,
                      int length) {
  bool attached = severity == Severity::note && !items_.empty();
  if (!count(severity)) return;
  Diagnostic d;
  d.severity = severity;
  d.loc = loc;
  d.message = std::move(message);
  d.attached = attached;
  if (file) {
    d.has_file = true;
    d.path = file->path;
    if (loc.known()) d.source_line = std::string(file->line(loc.line));
  }
  if (loc.known() && d.has_file) {
    int room = static_cast<int>(d.source_line.size()) - (loc.col - 1);
    d.length = length > 0 ? std::max(0, std::min(length, room)) : token_length(d.source_line, loc.col);
  }
  items_.push_back(std::move(d));
}

void Diagnostics::add(Diagnostic d) {
  if (d.attached && !last_kept_) return;
  if (count(d.severity)) items_.push_back(std::move(d));
}

const char* severity_name(Severity s) {
  switch (s) {
    case Severity::error: return "error";
    case Severity::warning: return "warning";
    case Severity::note: return "note";
  }
  return "error";
}

namespace {

// clang's colours: bold location and message, red errors, magenta warnings, cyan notes, a
// green caret and underline.
struct Paint {
  bool on = false;
  std::string operator()(const char* code, const std::string& text) const {
    return on ? std::string("\x1b[") + code + "m" + text + "\x1b[0m" : text;
  }
};

const char* severity_colour(Severity s) {
  switch (s) {
    case Severity::error: return "1;31";
    case Severity::warning: return "1;35";
    case Severity::note: return "1;36";
  }
  return "1;31";
}

// Control bytes and tabs would break the caret alignment or the terminal; the caret line
// repeats tabs so it still lines up under the column. A byte that is not valid UTF-8 is shown
// as \xNN: echoed raw it would garble the terminal, or the log it is written to.
std::string printable_line(std::string_view line) {
  std::string out;
  out.reserve(line.size());
  for (std::size_t i = 0; i < line.size();) {
    unsigned char c = static_cast<unsigned char>(line[i]);
    std::size_t n = utf8_sequence_length(line, i);
    if (n == 0) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
      ++i;
    } else if (n > 1) {
      out += line.substr(i, n);
      i += n;
    } else {
      out += (c == '\t' || c >= 0x20) && c != 0x7f ? char(c) : '?';
      ++i;
    }
  }
  return out;
}

/// Screen columns the byte at `i` takes in printable_line: 0 inside a UTF-8 character, 4
/// for an escaped byte, else 1.
int columns_of(std::string_view line, std::size_t i) {
  unsigned char c = static_cast<unsigned char>(line[i]);
  if ((c & 0xC0) == 0x80) {  // a continuation: inside a character, unless nothing valid starts it
    std::size_t start = i;
    while (start > 0 && i - start < 3 && (static_cast<unsigned char>(line[start]) & 0xC0) == 0x80) --start;
    std::size_t n = utf8_sequence_length(line, start);
    return n > 1 && start + n > i ? 0 : 4;
  }
  return utf8_sequence_length(line, i) == 0 ? 4 : 1;
}

std::string caret_line(std::string_view line, int col, int length, const Paint& paint) {
  std::string pad;
  for (int i = 0; i + 1 < col && static_cast<std::size_t>(i) < line.size(); ++i)
    pad += line[i] == '\t' ? std::string(1, '\t') : std::string(columns_of(line, i), ' ');
  std::string mark = "^";
  if (col >= 1 && static_cast<std::size_t>(col - 1) < line.size())
    mark += std::string(std::max(0, columns_of(line, col - 1) - 1), '~');
  for (int i = col; i < col - 1 + length && static_cast<std::size_t>(i) < line.size(); ++i)
    mark += std::string(columns_of(line, i), '~');
  return pad + paint("1;32", mark);
}

void format_one(const Diagnostic& d, const Paint& paint, std::string& out) {
  if (d.has_file) {
    std::string where = d.path;
    if (d.loc.known()) where += ":" + std::to_string(d.loc.line) + ":" + std::to_string(d.loc.col);
    out += paint("1", where + ":") + " ";
  }
  out += paint(severity_colour(d.severity), std::string(severity_name(d.severity)) + ":");
  out += " " + paint("1", d.message) + "\n";
  if (d.has_file && d.loc.known()) {
    std::string_view line = d.source_line;
    out += " " + printable_line(line) + "\n";
    out += " " + caret_line(line, d.loc.col, d.length, paint) + "\n";
  }
}

}  // namespace

std::string Diagnostics::format(FormatOptions options) const {
  // A diagnostic and the notes attached to it form a group; groups are ordered by file (in
  // the order the files were first reported), then by position within each file.
  // Diagnostics without a file rank as the path "" with has_file false.
  std::vector<std::vector<const Diagnostic*>> groups;
  for (const auto& d : items_) {
    if (d.attached && !groups.empty()) groups.back().push_back(&d);
    else groups.push_back({&d});
  }
  std::vector<std::pair<bool, std::string>> file_order;
  auto key = [](const Diagnostic* d) { return std::make_pair(d->has_file, d->path); };
  for (const auto& g : groups)
    if (std::find(file_order.begin(), file_order.end(), key(g[0])) == file_order.end())
      file_order.push_back(key(g[0]));
  auto rank = [&](const Diagnostic* d) {
    return static_cast<std::size_t>(std::find(file_order.begin(), file_order.end(), key(d)) - file_order.begin());
  };
  std::stable_sort(groups.begin(), groups.end(), [&](const auto& ga, const auto& gb) {
    const Diagnostic* a = ga[0];
    const Diagnostic* b = gb[0];
    std::size_t ra = rank(a), rb = rank(b);
    if (ra != rb) return ra < rb;
    if (a->loc.line != b->loc.line) return a->loc.line < b->loc.line;
    return a->loc.col < b->loc.col;
  });
  Paint paint{options.color};
  std::string out;
  for (const auto& g : groups)
    for (const Diagnostic* d : g) format_one(*d, paint, out);
  if (dropped_ > 0)
    out += paint("1;31", "error:") + " " + count_of(dropped_, "more error") + " not shown (limit " +
           std::to_string(max_errors) + "; raise it with --max-errors N, 0 for no limit)\n";
  return out;
}

std::string count_of(std::size_t n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

namespace {
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      bool same = std::tolower((unsigned char)a[i - 1]) == std::tolower((unsigned char)b[j - 1]);
      // A case-only difference costs little: SEQ_Drone2_Land vs SEQ_drone2_land is a typo.
      std::size_t subst = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : same ? 0 : 2);
      cur[j] = std::min({prev[j] + 2, cur[j - 1] + 2, subst});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}
}  // namespace

std::string closest_match(std::string_view word, const std::vector<std::string>& candidates) {
  if (word.size() > 200) return "";
  std::string best;
  std::size_t best_distance = SIZE_MAX;
  for (const auto& c : candidates) {
    if (c.size() > 200) continue;
    std::size_t d = edit_distance(word, c);
    if (d < best_distance) {
      best_distance = d;
      best = c;
    }
  }
  // Distances are doubled (case-only changes are free), so this allows about a third of
  // the word to differ, at least one edit: beyond that a suggestion is noise.
  std::size_t limit = std::max<std::size_t>(2, (word.size() * 2) / 3);
  if (best_distance == 0 && !best.empty() && best != word) return best;
  return best_distance <= limit ? best : "";
}

}  // namespace eamos
