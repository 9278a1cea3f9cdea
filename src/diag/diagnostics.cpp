#include "diag/diagnostics.h"

#include <algorithm>
#include <cctype>

namespace eamos {

void Diagnostics::error(const SourceFile* file, SourceLocation loc, std::string message) {
  add(Severity::error, file, loc, std::move(message));
}
void Diagnostics::warning(const SourceFile* file, SourceLocation loc, std::string message) {
  add(Severity::warning, file, loc, std::move(message));
}
void Diagnostics::note(const SourceFile* file, SourceLocation loc, std::string message) {
  add(Severity::note, file, loc, std::move(message));
}

// Counts the diagnostic and says whether to keep it (errors past max_errors are dropped).
bool Diagnostics::count(Severity severity) {
  if (severity == Severity::error) {
    ++error_count_;
    if (max_errors != 0 && error_count_ > max_errors) {
      ++dropped_;
      return false;
    }
  } else if (severity == Severity::warning) {
    ++warning_count_;
  }
  return true;
}

void Diagnostics::add(Severity severity, const SourceFile* file, SourceLocation loc,
                      std::string message) {
  if (!count(severity)) return;
  Diagnostic d;
  d.severity = severity;
  d.loc = loc;
  d.message = std::move(message);
  if (file) {
    d.has_file = true;
    d.path = file->path;
    if (loc.known()) d.source_line = std::string(file->line(loc.line));
  }
  items_.push_back(std::move(d));
}

void Diagnostics::add(Diagnostic d) {
  if (count(d.severity)) items_.push_back(std::move(d));
}

namespace {

const char* severity_name(Severity s) {
  switch (s) {
    case Severity::error: return "error";
    case Severity::warning: return "warning";
    case Severity::note: return "note";
  }
  return "error";
}

// Control bytes and tabs would break the caret alignment or the terminal; the caret line
// repeats tabs so it still lines up under the column.
std::string printable_line(std::string_view line) {
  std::string out;
  out.reserve(line.size());
  for (unsigned char c : line) out += (c == '\t' || c >= 0x20) && c != 0x7f ? char(c) : '?';
  return out;
}

std::string caret_line(std::string_view line, int col) {
  std::string out;
  for (int i = 0; i + 1 < col && static_cast<std::size_t>(i) < line.size(); ++i)
    out += line[i] == '\t' ? '\t' : ' ';
  out += '^';
  return out;
}

}  // namespace

std::string Diagnostics::format() const {
  // Files in the order they were first reported, then by position within each file.
  // Diagnostics without a file rank as the path "" with has_file false.
  std::vector<std::pair<bool, std::string>> file_order;
  auto key = [](const Diagnostic* d) { return std::make_pair(d->has_file, d->path); };
  auto rank = [&](const Diagnostic* d) {
    auto it = std::find(file_order.begin(), file_order.end(), key(d));
    return static_cast<std::size_t>(it - file_order.begin());
  };
  for (const auto& d : items_)
    if (std::find(file_order.begin(), file_order.end(), key(&d)) == file_order.end())
      file_order.push_back(key(&d));
  std::vector<const Diagnostic*> sorted;
  for (const auto& d : items_) sorted.push_back(&d);
  std::stable_sort(sorted.begin(), sorted.end(), [&](const Diagnostic* a, const Diagnostic* b) {
    std::size_t ra = rank(a), rb = rank(b);
    if (ra != rb) return ra < rb;
    if (a->loc.line != b->loc.line) return a->loc.line < b->loc.line;
    return a->loc.col < b->loc.col;
  });
  std::string out;
  for (const Diagnostic* d : sorted) {
    if (d->has_file) {
      out += d->path;
      if (d->loc.known()) out += ":" + std::to_string(d->loc.line) + ":" + std::to_string(d->loc.col);
      out += ": ";
    }
    out += severity_name(d->severity);
    out += ": " + d->message + "\n";
    if (d->has_file && d->loc.known()) {
      std::string_view line = d->source_line;
      out += " " + printable_line(line) + "\n";
      out += " " + caret_line(line, d->loc.col) + "\n";
    }
  }
  if (dropped_ > 0)
    out += "error: " + std::to_string(dropped_) + " more errors not shown (limit " +
           std::to_string(max_errors) + "; raise it with --max-errors N, 0 for no limit)\n";
  return out;
}

namespace {
std::size_t edit_distance(const std::string& a, const std::string& b) {
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

std::string closest_match(const std::string& word, const std::vector<std::string>& candidates) {
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
