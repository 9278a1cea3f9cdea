#pragma once
// The command line read as a compiler reads a source: an error names the argument, shows the
// command with a caret under it, says how to fix it and suggests the name meant ("did you
// mean"). Validators state their ranges in words; output paths are checked before anything
// runs; colour follows --color, the terminal and NO_COLOR.
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace eamos::cli {

/// How the CLI prints diagnostics, set once from --color and --diagnostics-format.
struct OutputStyle {
  bool color_stderr = false;         ///< ANSI colour in what goes to standard error
  std::string diagnostics = "text";  ///< text | json | sarif
};
OutputStyle& output_style();

/// --color: "always", "never" or "auto" (a terminal on `fd`, TERM not "dumb", NO_COLOR unset or empty).
bool use_color(const std::string& when, int fd);
/// The value of --color in argv, before CLI11 parses it ("auto" when absent or malformed).
std::string color_argument(const std::vector<std::string>& args);
/// --log-level (empty: not given) for the libraries' log (diag/log.h), exported as
/// EAMOS_LOG_LEVEL so the processes this one starts log alike; warns of an EAMOS_LOG_LEVEL that
/// names no level.
void apply_log_level(const std::string& argument);
/// "eamos: error: ", in red when colour is on.
std::string error_prefix();

/// Validators whose messages state their bounds in words ("a number greater than 0").
CLI::Validator positive();
CLI::Validator non_negative();
CLI::Validator whole_number(long long lo, long long hi);
CLI::Validator number_between(double lo, double hi);
CLI::Validator one_of(std::vector<std::string> names);
CLI::Validator existing_file(const std::string& what);
CLI::Validator existing_folder(const std::string& what);

/// An argument to point at: index into args, and the bytes [offset, offset + length) of it.
struct ArgSpot {
  int index = -1;  ///< -1: none; args.size(): just past the last one (something is missing)
  std::size_t offset = 0;
  std::size_t length = 0;
};
/// `eamos: error: message`, then the command line with a caret and underline under `at`.
std::string argument_error(const std::vector<std::string>& args, ArgSpot at, const std::string& message);

/// Unknown commands and options, each with the closest known name; "" when all are known.
/// Runs before CLI11 parses (which says only "A subcommand is required" or "not expected").
std::string unknown_names(CLI::App& app, const std::vector<std::string>& args);
/// What a CLI11 parse error means, said with the argument it is about.
std::string explain_parse_error(CLI::App& app, const std::vector<std::string>& args, const CLI::ParseError& e);

/// An output file or folder named by an option: checked before anything runs.
struct OutputPath {
  CLI::Option* option = nullptr;
  bool folder = false;  ///< a folder made if missing (compile -o) rather than a file
};
/// Every problem with the given outputs (missing folder, not writable, a folder where a file
/// goes, two options writing one file, an output that is an input); "" when all can be written.
std::string check_outputs(CLI::App& sub, const std::vector<std::string>& args, const std::vector<OutputPath>& outputs,
                          const std::vector<std::string>& inputs);

}  // namespace eamos::cli
