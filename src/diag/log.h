#pragma once
// The one way a library reports what its caller did not ask for (a dropped frame, a receive
// thread that stopped, an autopilot's text): one line per message on standard error,
//   eamos COMPONENT[ SUBJECT]: LEVEL: TEXT
// e.g. `eamos mavlink Drone2: warning: dropped a frame of system 2: bad CRC`. Output that a
// command was asked for (reports, diagnostics of a mission) is the CLI's, not the log's.
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace eamos::diag {

/// Most severe first: a level shows its own messages and every more severe one.
enum class LogLevel { error, warning, info, debug };

/// "error", "warning", "info", "debug".
std::string_view log_level_name(LogLevel level);
/// The level called `name`, or nullopt for anything else.
std::optional<LogLevel> parse_log_level(std::string_view name);

/// The environment variable a level is taken from (so a DEX a launch starts inherits it).
inline constexpr const char* kLogLevelVariable = "EAMOS_LOG_LEVEL";
/// The level before anyone sets one: EAMOS_LOG_LEVEL when it names a level, else info.
LogLevel default_log_level();

/// Messages less severe than `level` are dropped from now on, in every thread.
void set_log_level(LogLevel level);
LogLevel log_level();
/// Whether a message at `level` would be written (to skip building an expensive one).
bool log_enabled(LogLevel level);

/// Where lines go (each without its newline); an empty function restores standard error.
/// Returns the previous sink. Lines reach the sink one at a time, from any thread.
using LogSink = std::function<void(std::string_view line)>;
LogSink set_log_sink(LogSink sink);

/// `eamos component[ subject]: level: text`; `subject` may be empty. Never throws.
std::string format_log_line(LogLevel level, std::string_view component, std::string_view subject,
                            std::string_view text);
/// Writes the line when `level` is enabled. Never throws: a log line must not end a flight.
void log(LogLevel level, std::string_view component, std::string_view subject, std::string_view text) noexcept;

/// A component's (and a subject's, such as a drone's) logger.
struct Logger {
  std::string component;  ///< the library: "mavlink", "dex", "transport", ...
  std::string subject;    ///< what it is about ("Drone2", a link's URL), or empty

  void error(std::string_view text) const noexcept { log(LogLevel::error, component, subject, text); }
  void warning(std::string_view text) const noexcept { log(LogLevel::warning, component, subject, text); }
  void info(std::string_view text) const noexcept { log(LogLevel::info, component, subject, text); }
  void debug(std::string_view text) const noexcept { log(LogLevel::debug, component, subject, text); }
};

}  // namespace eamos::diag
