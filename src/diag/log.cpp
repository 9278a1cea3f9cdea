#include "diag/log.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <mutex>

namespace eamos::diag {

namespace {

std::atomic<int>& level_store() {
  static std::atomic<int> level{static_cast<int>(default_log_level())};
  return level;
}

// One lock for the sink and the writing: lines from different threads never interleave.
std::mutex& sink_mutex() {
  static std::mutex m;
  return m;
}

LogSink& sink_store() {
  static LogSink sink;
  return sink;
}

}  // namespace

std::string_view log_level_name(LogLevel level) {
  switch (level) {
    case LogLevel::error: return "error";
    case LogLevel::warning: return "warning";
    case LogLevel::info: return "info";
    case LogLevel::debug: return "debug";
  }
  return "info";
}

std::optional<LogLevel> parse_log_level(std::string_view name) {
  for (LogLevel l : {LogLevel::error, LogLevel::warning, LogLevel::info, LogLevel::debug})
    if (name == log_level_name(l)) return l;
  return std::nullopt;
}

LogLevel default_log_level() {
  const char* env = std::getenv(kLogLevelVariable);
  std::optional<LogLevel> level = env ? parse_log_level(env) : std::nullopt;
  return level.value_or(LogLevel::info);
}

void set_log_level(LogLevel level) { level_store().store(static_cast<int>(level)); }

LogLevel log_level() { return static_cast<LogLevel>(level_store().load()); }

bool log_enabled(LogLevel level) { return static_cast<int>(level) <= level_store().load(); }

LogSink set_log_sink(LogSink sink) {
  std::lock_guard lock(sink_mutex());
  LogSink previous = std::move(sink_store());
  sink_store() = std::move(sink);
  return previous;
}

std::string format_log_line(LogLevel level, std::string_view component, std::string_view subject,
                            std::string_view text) {
  std::string line = "eamos ";
  line += component;
  if (!subject.empty()) (line += ' ') += subject;
  line += ": ";
  line += log_level_name(level);
  line += ": ";
  line += text;
  return line;
}

void log(LogLevel level, std::string_view component, std::string_view subject, std::string_view text) noexcept {
  if (!log_enabled(level)) return;
  try {
    std::string line = format_log_line(level, component, subject, text);
    std::lock_guard lock(sink_mutex());
    if (sink_store()) return sink_store()(line);
    line += '\n';
    std::fwrite(line.data(), 1, line.size(), stderr);
  } catch (...) {
    // Out of memory, or a sink that threw: the message is lost, the caller goes on.
    std::fputs("eamos: a log message was lost\n", stderr);
  }
}

}  // namespace eamos::diag
