#include "cli/arguments.h"

#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "diag/diagnostics.h"
#include "diag/log.h"
#include "diag/number.h"

namespace eamos::cli {

using diag::number_text;

namespace fs = std::filesystem;

OutputStyle& output_style() {
  static OutputStyle style;
  return style;
}

bool use_color(const std::string& when, int fd) {
  if (when == "always") return true;
  if (when == "never") return false;
  const char* no_color = std::getenv("NO_COLOR");
  const char* term = std::getenv("TERM");
  return isatty(fd) && !(no_color && *no_color) && !(term && std::strcmp(term, "dumb") == 0);
}

void apply_log_level(const std::string& argument) {
  if (!argument.empty()) {
    diag::set_log_level(diag::parse_log_level(argument).value_or(diag::LogLevel::info));
    setenv(diag::kLogLevelVariable, argument.c_str(), 1);
    return;
  }
  const char* env = std::getenv(diag::kLogLevelVariable);
  if (env && !diag::parse_log_level(env))
    std::cerr << "eamos: warning: " << diag::kLogLevelVariable << "='" << env
              << "' is not a log level; info is used (set it to error, warning, info or debug)\n";
}

std::string color_argument(const std::vector<std::string>& args) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i].rfind("--color=", 0) == 0) return args[i].substr(8);
    if (args[i] == "--color" && i + 1 < args.size()) return args[i + 1];
  }
  return "auto";
}

namespace {

std::string paint(const char* code, const std::string& text) {
  return output_style().color_stderr ? std::string("\x1b[") + code + "m" + text + "\x1b[0m" : text;
}

// Whole text parsed as a finite number.
bool parse_number(const std::string& s, double& out) {
  if (s.empty() || std::isspace(static_cast<unsigned char>(s[0]))) return false;
  char* end = nullptr;
  errno = 0;
  out = std::strtod(s.c_str(), &end);
  return *end == '\0' && errno == 0 && std::isfinite(out);
}

bool parse_whole(const std::string& s, long long& out) {
  if (s.empty() || std::isspace(static_cast<unsigned char>(s[0]))) return false;
  char* end = nullptr;
  errno = 0;
  out = std::strtoll(s.c_str(), &end, 10);
  return *end == '\0' && errno == 0;
}

std::string in_quotes(const std::string& s) { return "'" + s + "'"; }

std::string joined(const std::vector<std::string>& names, const std::string& separator = ", ") {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : separator) + n;
  return out;
}

}  // namespace

std::string error_prefix() { return "eamos: " + paint("1;31", "error:") + " "; }

CLI::Validator positive() {
  return CLI::Validator(
      [](std::string& in) {
        double v;
        return parse_number(in, v) && v > 0 ? std::string() : in_quotes(in) + " is not a number greater than 0";
      },
      "NUMBER > 0");
}

CLI::Validator non_negative() {
  return CLI::Validator(
      [](std::string& in) {
        double v;
        return parse_number(in, v) && v >= 0 ? std::string() : in_quotes(in) + " is not a number of 0 or more";
      },
      "NUMBER >= 0");
}

CLI::Validator whole_number(long long lo, long long hi) {
  std::string range = std::to_string(lo) + " to " + std::to_string(hi);
  return CLI::Validator(
      [lo, hi, range](std::string& in) {
        long long v;
        return parse_whole(in, v) && v >= lo && v <= hi ? std::string()
                                                         : in_quotes(in) + " is not a whole number from " + range;
      },
      "WHOLE NUMBER " + range);
}

CLI::Validator number_between(double lo, double hi) {
  std::string range = number_text(lo) + " to " + number_text(hi);
  return CLI::Validator(
      [lo, hi, range](std::string& in) {
        double v;
        return parse_number(in, v) && v >= lo && v <= hi ? std::string() : in_quotes(in) + " is not a number from " + range;
      },
      "NUMBER " + range);
}

CLI::Validator one_of(std::vector<std::string> names) {
  std::string list = joined(names);
  return CLI::Validator(
      [names, list](std::string& in) {
        for (const std::string& n : names)
          if (n == in) return std::string();
        std::string near = closest_match(in, names);
        return in_quotes(in) + " is not one of " + list + (near.empty() ? "" : "; did you mean " + in_quotes(near) + "?");
      },
      joined(names, "|"));
}

namespace {

// A close name among the files beside a path that does not exist ("did you mean").
std::string sibling_suggestion(const std::string& path) {
  fs::path p(path);
  fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  std::error_code ec;
  std::vector<std::string> names;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end && names.size() < 2000; it.increment(ec))
    names.push_back(it->path().filename().string());
  std::string near = closest_match(p.filename().string(), names);
  if (near.empty()) return "";
  return "; did you mean " + in_quotes((p.parent_path().empty() ? fs::path(near) : p.parent_path() / near).string()) + "?";
}

}  // namespace

CLI::Validator existing_file(const std::string& what) {
  return CLI::Validator(
      [what](std::string& in) {
        std::error_code ec;
        if (fs::is_directory(in, ec)) return in_quotes(in) + " is a folder, not " + what;
        if (!fs::exists(in, ec)) return "no file " + in_quotes(in) + sibling_suggestion(in);
        return std::string();
      },
      "FILE");
}

CLI::Validator existing_folder(const std::string& what) {
  return CLI::Validator(
      [what](std::string& in) {
        std::error_code ec;
        if (fs::is_directory(in, ec)) return std::string();
        if (!fs::exists(in, ec)) return "no folder " + in_quotes(in) + sibling_suggestion(in);
        if (fs::path(in).extension() == ".eamos")
          return in_quotes(in) + " is a mission, not " + what + "; compile it first (`eamos compile " + in +
                 " -o DIR`), or fly it as separate processes with `eamos run " + in + " --distributed`";
        return in_quotes(in) + " is a file, not " + what;
      },
      "FOLDER");
}

namespace {

bool needs_quotes(const std::string& s) {
  if (s.empty()) return true;
  for (unsigned char c : s)
    if (!std::isalnum(c) && std::string_view("_./:=,+@%-").find(static_cast<char>(c)) == std::string_view::npos)
      return true;
  return false;
}

}  // namespace

std::string argument_error(const std::vector<std::string>& args, ArgSpot at, const std::string& message) {
  std::string out = error_prefix() + paint("1", message) + "\n";
  if (at.index < 0) return out;
  std::string line = "eamos";
  std::size_t column = 0, width = 1;
  for (std::size_t i = 0; i <= args.size(); ++i) {
    if (static_cast<int>(i) == at.index) {
      column = line.size() + 1 + (i < args.size() && needs_quotes(args[i]) ? 1 : 0) + at.offset;
      width = std::max<std::size_t>(1, at.length);
    }
    if (i == args.size()) break;
    line += " " + (needs_quotes(args[i]) ? in_quotes(args[i]) : args[i]);
  }
  out += " " + line + "\n";
  out += " " + std::string(column, ' ') + paint("1;32", "^" + std::string(width - 1, '~')) + "\n";
  return out;
}

namespace {

const std::vector<std::string> kValuedAppOptions = {"--color", "--diagnostics-format", "--log-level"};

bool looks_like_option(const std::string& t) {
  return t.size() >= 2 && t[0] == '-' && (t[1] == '-' ? t.size() > 2 : std::isalpha(static_cast<unsigned char>(t[1])));
}

std::string option_name(const std::string& t) { return t.substr(0, t.find('=')); }

// The command's position in args: the first word that is not an option or an option's value.
int command_index(const std::vector<std::string>& args) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& t = args[i];
    if (t == "--") return -1;
    if (!looks_like_option(t)) return static_cast<int>(i);
    for (const std::string& v : kValuedAppOptions)
      if (t == v) ++i;
  }
  return -1;
}

std::vector<CLI::App*> commands(CLI::App& app) {
  return app.get_subcommands([](CLI::App*) { return true; });
}

std::vector<std::string> command_names(CLI::App& app) {
  std::vector<std::string> names;
  for (CLI::App* c : commands(app)) names.push_back(c->get_name());
  return names;
}

std::vector<std::string> option_names(CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* o : app.get_options()) {
    for (const std::string& l : o->get_lnames()) names.push_back("--" + l);
    for (const std::string& s : o->get_snames()) names.push_back("-" + s);
  }
  return names;
}

bool has_option(CLI::App& app, const std::string& name) {
  for (const std::string& n : option_names(app))
    if (n == name) return true;
  return false;
}

CLI::App* command_at(CLI::App& app, const std::vector<std::string>& args) {
  int ci = command_index(args);
  if (ci < 0) return nullptr;
  for (CLI::App* c : commands(app))
    if (c->get_name() == args[ci]) return c;
  return nullptr;
}

std::string unknown_option(CLI::App& app, CLI::App* sub, const std::string& name) {
  std::vector<std::string> known = option_names(app);
  if (sub) {
    std::vector<std::string> own = option_names(*sub);
    known.insert(known.end(), own.begin(), own.end());
  }
  std::string where = sub ? "`eamos " + sub->get_name() + "`" : "eamos";
  std::string near = closest_match(name, known);
  if (!near.empty()) return "unknown option " + in_quotes(name) + " of " + where + "; did you mean " + in_quotes(near) + "?";
  std::vector<std::string> others;
  for (CLI::App* c : commands(app))
    if (c != sub && has_option(*c, name)) others.push_back(c->get_name());
  if (!others.empty())
    return in_quotes(name) + " is an option of `eamos " + joined(others, "`, `eamos ") + "`, not of " + where;
  return "unknown option " + in_quotes(name) + " of " + where + "; `eamos " + (sub ? sub->get_name() + " " : "") +
         "--help` lists them";
}

}  // namespace

std::string unknown_names(CLI::App& app, const std::vector<std::string>& args) {
  int ci = command_index(args);
  std::string out;
  if (ci >= 0 && !command_at(app, args)) {
    std::string near = closest_match(args[ci], command_names(app));
    out += argument_error(args, {ci, 0, args[ci].size()},
                          "unknown command " + in_quotes(args[ci]) +
                              (near.empty() ? "; the commands are " + joined(command_names(app))
                                            : "; did you mean " + in_quotes(near) + "?"));
  }
  CLI::App* sub = command_at(app, args);
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& t = args[i];
    if (t == "--") break;
    if (!looks_like_option(t) || static_cast<int>(i) == ci) continue;
    std::string name = option_name(t);
    bool before_command = ci < 0 || static_cast<int>(i) < ci;
    if (has_option(app, name) || (!before_command && sub && has_option(*sub, name))) {
      for (const std::string& v : kValuedAppOptions)
        if (t == v) ++i;  // its value is not an option
      continue;
    }
    if (name == "-h" || name == "--help" || name == "--version") continue;
    out += argument_error(args, {static_cast<int>(i), 0, name.size()},
                          unknown_option(app, before_command ? nullptr : sub, name));
  }
  if (ci < 0 && out.empty()) {
    bool asks = false;
    for (const std::string& t : args) asks |= t == "-h" || t == "--help" || t == "--version";
    if (!asks)
      out += argument_error(args, {},
                            "no command given; say what to do: eamos COMMAND …, where COMMAND is one of " +
                                joined(command_names(app)) + " (eamos --help)");
  }
  return out;
}

namespace {

// Where an option (any of its names) is given: the spot of its value (or of the option
// when it has none), the last time it is given.
ArgSpot option_spot(const CLI::Option* opt, const std::vector<std::string>& args, const std::string& value = "",
                    bool want_value = true) {
  ArgSpot spot;
  std::vector<std::string> names;
  for (const std::string& l : opt->get_lnames()) names.push_back("--" + l);
  for (const std::string& s : opt->get_snames()) names.push_back("-" + s);
  for (std::size_t i = 0; i < args.size(); ++i) {
    for (const std::string& n : names) {
      if (args[i] == n) {
        bool has_next = i + 1 < args.size();
        if (want_value && has_next && (value.empty() || args[i + 1] == value))
          spot = {static_cast<int>(i + 1), 0, args[i + 1].size()};
        else if (!want_value || value.empty())
          spot = {static_cast<int>(i), want_value ? n.size() : 0, want_value ? 1 : n.size()};
      } else if (args[i].rfind(n + "=", 0) == 0) {
        std::size_t at = n.size() + 1;
        spot = want_value ? ArgSpot{static_cast<int>(i), at, args[i].size() - at} : ArgSpot{static_cast<int>(i), 0, n.size()};
      }
    }
  }
  if (spot.index < 0 && !value.empty() && opt->get_lnames().empty() && opt->get_snames().empty())
    for (std::size_t i = 0; i < args.size(); ++i)
      if (args[i] == value) spot = {static_cast<int>(i), 0, value.size()};
  return spot;
}

const CLI::Option* find_option(CLI::App& app, const std::vector<std::string>& args, const std::string& name) {
  if (CLI::App* sub = command_at(app, args))
    if (const CLI::Option* o = sub->get_option_no_throw(name)) return o;
  return app.get_option_no_throw(name);
}

std::string first_quoted(const std::string& s) {
  std::size_t a = s.find('\'');
  std::size_t b = a == std::string::npos ? a : s.find('\'', a + 1);
  return b == std::string::npos ? "" : s.substr(a + 1, b - a - 1);
}

std::string display(const CLI::Option* o, const std::string& fallback) {
  if (!o) return fallback;
  if (!o->get_lnames().empty()) return "--" + o->get_lnames().front();
  if (!o->get_snames().empty()) return "-" + o->get_snames().front();
  return o->get_name();
}

/// The class, not get_name(): an ExtrasError carries the command's name there.
std::string error_kind(const CLI::ParseError& e) {
  return dynamic_cast<const CLI::ValidationError*>(&e)   ? "ValidationError"
         : dynamic_cast<const CLI::RequiredError*>(&e)    ? "RequiredError"
         : dynamic_cast<const CLI::ArgumentMismatch*>(&e) ? "ArgumentMismatch"
         : dynamic_cast<const CLI::ExcludesError*>(&e)    ? "ExcludesError"
         : dynamic_cast<const CLI::RequiresError*>(&e)    ? "RequiresError"
         : dynamic_cast<const CLI::ExtrasError*>(&e)      ? "ExtrasError"
         : dynamic_cast<const CLI::ConversionError*>(&e)  ? "ConversionError"
                                                          : e.get_name();
}

/// A parse error as CLI11 words it, with the command it happened in.
struct ParseFailure {
  CLI::App& app;
  const std::vector<std::string>& args;
  std::string what;     ///< CLI11's text
  CLI::App* sub;        ///< the subcommand on the line, or null
  std::string command;  ///< "`eamos SUB`" or "eamos"
};

std::string explain_required(const ParseFailure& f) {
  std::string name = f.what.substr(0, f.what.find(" is required"));
  const CLI::Option* o = find_option(f.app, f.args, name);
  std::string desc = o ? o->get_description() : "";
  bool positional = o && o->get_lnames().empty() && o->get_snames().empty();
  std::string needs = positional ? "the " + name + (desc.empty() ? "" : " (" + desc + ")")
                                 : display(o, name) + (desc.empty() ? "" : " (" + desc + ")");
  return argument_error(f.args, {static_cast<int>(f.args.size()), 0, 1}, f.command + " needs " + needs);
}

std::string explain_pair(const ParseFailure& f, bool excludes) {
  std::string verb = excludes ? " excludes " : " requires ";
  std::size_t v = f.what.find(verb);
  std::string a = f.what.substr(0, v), b = v == std::string::npos ? "" : f.what.substr(v + verb.size());
  const CLI::Option* oa = find_option(f.app, f.args, a);
  const CLI::Option* ob = find_option(f.app, f.args, b);
  if (excludes) {
    ArgSpot at = ob ? option_spot(ob, f.args, "", false) : ArgSpot{};
    ArgSpot first = oa ? option_spot(oa, f.args, "", false) : ArgSpot{};
    if (first.index > at.index) at = first;
    return argument_error(f.args, at, display(oa, a) + " and " + display(ob, b) + " cannot be given together; keep one");
  }
  return argument_error(f.args, oa ? option_spot(oa, f.args, "", false) : ArgSpot{},
                        display(oa, a) + " needs " + display(ob, b) + " too");
}

/// Every unexpected argument, each with its caret; "" when none of them is on the line.
std::string explain_extras(const ParseFailure& f) {
  std::string out;
  std::string list = f.what.substr(f.what.find(": ") + 2);
  for (std::size_t i = 0; i < f.args.size(); ++i) {
    const std::string& arg = f.args[i];
    if (static_cast<int>(i) == command_index(f.args) || looks_like_option(arg)) continue;
    std::size_t p = list.find(arg);
    if (p == std::string::npos) continue;
    bool word = (p == 0 || list[p - 1] == ' ') && (p + arg.size() == list.size() || list[p + arg.size()] == ' ');
    if (!word) continue;
    out += argument_error(f.args, {static_cast<int>(i), 0, arg.size()},
                          "unexpected argument " + in_quotes(arg) + " of " + f.command + "; `eamos " +
                              (f.sub ? f.sub->get_name() + " " : "") + "--help` says what it takes");
  }
  return out;
}

/// "" when the option is not found.
std::string explain_conversion(const ParseFailure& f) {
  const std::string& what = f.what;
  std::string name = what.rfind("Could not convert: ", 0) == 0 ? what.substr(19, what.find(" = ") - 19) : "";
  const CLI::Option* o = name.empty() ? nullptr : find_option(f.app, f.args, name);
  if (!o) return "";
  return argument_error(f.args, option_spot(o, f.args),
                        display(o, name) + ": " + in_quotes(what.substr(what.find(" = ") + 3)) +
                            " is not a value it takes; `eamos " + (f.sub ? f.sub->get_name() + " " : "") +
                            "--help` says which");
}

}  // namespace

std::string explain_parse_error(CLI::App& app, const std::vector<std::string>& args, const CLI::ParseError& e) {
  std::string kind = error_kind(e);
  CLI::App* sub = command_at(app, args);
  ParseFailure f{app, args, e.what(), sub, sub ? "`eamos " + sub->get_name() + "`" : "eamos"};
  std::size_t colon = f.what.find(": ");
  std::string head = colon == std::string::npos ? f.what : f.what.substr(0, colon);
  std::string rest = colon == std::string::npos ? "" : f.what.substr(colon + 2);
  if (kind == "ValidationError") {
    const CLI::Option* o = find_option(app, args, head);
    bool positional = o && o->get_lnames().empty() && o->get_snames().empty();
    ArgSpot at = o ? option_spot(o, args, first_quoted(rest)) : ArgSpot{};
    return argument_error(args, at, positional ? rest : display(o, head) + ": " + rest);
  }
  if (kind == "RequiredError") return explain_required(f);
  if (kind == "ArgumentMismatch") {
    const CLI::Option* o = find_option(app, args, head);
    ArgSpot at = o ? option_spot(o, args, "", false) : ArgSpot{};
    if (at.index >= 0) at = {at.index, at.length, 1};
    return argument_error(args, at, display(o, head) + " needs a value");
  }
  if (kind == "ExcludesError" || kind == "RequiresError") return explain_pair(f, kind == "ExcludesError");
  if (kind == "ExtrasError")
    if (std::string out = explain_extras(f); !out.empty()) return out;
  if (kind == "ConversionError")
    if (std::string out = explain_conversion(f); !out.empty()) return out;
  return argument_error(args, {}, f.what);
}

std::string check_outputs(CLI::App& sub, const std::vector<std::string>& args, const std::vector<OutputPath>& outputs,
                          const std::vector<std::string>& inputs) {
  (void)sub;
  std::string out;
  std::vector<std::pair<fs::path, const CLI::Option*>> seen;
  for (const OutputPath& o : outputs) {
    if (!o.option || o.option->count() == 0) continue;
    std::string path = o.option->as<std::string>();
    if (path.empty()) {  // given, but as "" (an unset shell variable): never the working folder
      out += argument_error(args, option_spot(o.option, args, path), display(o.option, "") + ": an empty path; " +
                            (o.folder ? "name a folder (made if missing)" : "name a file, or leave the option out"));
      continue;
    }
    if (!o.folder && path == "-") continue;
    ArgSpot at = option_spot(o.option, args, path);
    std::string name = display(o.option, "");
    std::error_code ec;
    auto fail = [&](const std::string& why) { out += argument_error(args, at, name + ": " + why); };
    fs::path p(path);
    fs::path canonical = fs::weakly_canonical(p, ec);
    bool clash = false;
    for (const auto& [other, option] : seen)
      if (!ec && other == canonical) {
        fail(display(option, "") + " writes " + in_quotes(path) + " too; give each its own file");
        clash = true;
      }
    for (const std::string& in : inputs)
      if (!clash && !in.empty() && fs::exists(in, ec) && fs::equivalent(in, p, ec)) {
        fail(in_quotes(path) + " is an input of this command; writing it would destroy it");
        clash = true;
      }
    if (clash) continue;
    if (!ec) seen.push_back({canonical, o.option});
    if (fs::exists(p, ec)) {
      bool dir = fs::is_directory(p, ec);
      if (o.folder && !dir) fail(in_quotes(path) + " is a file, not a folder; name a folder (made if missing)");
      else if (!o.folder && dir) fail(in_quotes(path) + " is a folder; give a file path (inside it, or elsewhere)");
      else if (access(path.c_str(), W_OK) != 0) fail("cannot write " + in_quotes(path) + ": " + std::strerror(errno));
      continue;
    }
    // The nearest folder that exists must take new files (compile -o makes the rest).
    fs::path parent = p.parent_path().empty() ? fs::path(".") : p.parent_path();
    if (o.folder)
      while (!fs::exists(parent, ec) && parent.has_parent_path() && parent.parent_path() != parent)
        parent = parent.parent_path();
    if (!fs::exists(parent, ec))
      fail("the folder " + in_quotes(parent.string()) + " does not exist; create it (mkdir -p " + parent.string() +
           ") or write elsewhere");
    else if (!fs::is_directory(parent, ec))
      fail(in_quotes(parent.string()) + " is a file, not a folder");
    else if (access(parent.c_str(), W_OK | X_OK) != 0)
      fail("cannot create " + in_quotes(path) + " in " + in_quotes(parent.string()) + ": " + std::strerror(errno));
  }
  return out;
}

}  // namespace eamos::cli
