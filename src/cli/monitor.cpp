// `eamos monitor TRACE.jsonl` (replay a finished mission in the browser) and the views
// `eamos run --monitor` / `eamos launch --monitor` serve live (src/monitor).
#include <condition_variable>
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <mutex>

#include "cli/arguments.h"
#include "cli/commands.h"
#include "cli/signal_watch.h"
#include "deploy/manifest.h"
#include "deploy/mission_file.h"
#include "diag/file_read.h"
#include "diag/source.h"
#include "monitor/mission_view.h"
#include "monitor/server.h"
#include "monitor/trace_file.h"

namespace eamos::cli {

namespace {

monitor::SvgRenderer dot_renderer() {
  return [](const std::string& dot, std::string& svg, std::string& error) { return render_svg(dot, svg, error); };
}

std::string read_text(const std::string& path) {
  std::string text;
  diag::read_bounded_file(path, kMaxSourceFileBytes, text, diag::Pipes::read);
  return text;
}

// The trace's embedded mission (schema v1 header) compiled again, for the graphs.
bool compile_header(const nlohmann::json& header, graph::Compilation& c, std::string& why) {
  std::string name = header.value("mission", std::string("mission.eamos"));
  std::string fleet_text = header.value("fleet", std::string());
  Diagnostics diags;
  fleet::Fleet fleet;
  if (!fleet_text.empty())
    fleet::parse_fleet(std::make_shared<SourceFile>(name + " (fleet in the trace)", fleet_text), fleet, diags);
  auto source = std::make_shared<SourceFile>(name + " (in the trace)", header.value("source", std::string()));
  if (graph::compile(source, fleet, diags, c) && !diags.has_errors()) return true;
  why = "the mission in the trace does not compile here:\n" + diags.format();
  return false;
}

// The page's mission for a replay: from --mission when given, else the trace's header.
bool replay_view(const MonitorCommandOptions& m, const monitor::LoadedTrace& trace, nlohmann::json& view) {
  monitor::ViewInput in;
  graph::Compilation c;
  std::string why, warnings;
  if (!m.mission.empty()) {
    CommonOptions o;
    o.mission = m.mission;
    o.fleet = m.fleet;
    o.quiet = true;
    if (!compile_and_report(o, c)) return false;
    in.mission_name = m.mission;
    in.fleet_text = m.fleet.empty() ? "" : read_text(m.fleet);
  } else if (trace.header && trace.header->value("source", std::string()).size() > 0) {
    in.mission_name = trace.header->value("mission", std::string());
    in.fleet_text = trace.header->value("fleet", std::string());
    if (!compile_header(*trace.header, c, why)) {
      std::cerr << "eamos monitor: warning: " << why << "the page shows the lanes only\n";
      view = monitor::bare_view(in, "the mission in the trace does not compile: lanes only");
      return true;
    }
  } else {
    in.mission_name = m.trace;
    view = monitor::bare_view(in, "this trace names no mission (no header line): lanes only; "
                                  "`eamos monitor TRACE --mission FILE.eamos` adds the graphs and the text");
    return true;
  }
  view = monitor::mission_view(c, in, dot_renderer(), warnings);
  if (!warnings.empty()) std::cerr << "eamos monitor: warning: " << warnings;
  return true;
}

// A file that is plainly not a trace (a mission, a summary, anything whose first line is not
// a JSON object) is said so once, instead of one "not valid JSON" per line.
std::string not_a_trace(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string first;
  while (first.find_first_not_of(" \t\r") == std::string::npos && std::getline(in, first)) {
  }
  if (first.find_first_not_of(" \t\r") == std::string::npos) return "";  // empty: the reader says so
  nlohmann::json j = nlohmann::json::parse(first, nullptr, false);
  // A trace's header carries the mission's source: a first line that is an event is a trace.
  if (j.is_object() && j.contains("event")) return "";
  std::string text = first + "\n" + std::string(std::istreambuf_iterator<char>(in), {}).substr(0, 1 << 16);
  bool mission = std::filesystem::path(path).extension() == ".eamos" || text.find("func INIT") != std::string::npos ||
                 text.rfind("var ", 0) == 0 || text.rfind("package ", 0) == 0 || text.rfind("//", 0) == 0;
  if (mission)
    return "'" + path + "' is a mission, not a trace; watch it fly with `eamos run " + path +
           " --monitor 8080`, or record a trace with `eamos run " + path + " --trace run.jsonl` and replay that";
  if (nlohmann::json::parse(text, nullptr, false).is_object())
    return "'" + path + "' is one JSON document (a summary or a graph?), not a trace: a trace has one event per "
           "line, as `eamos run --trace` writes it";
  if (!j.is_object())
    return "'" + path + "' is not a trace: its first line is not a JSON object; give the file `eamos run --trace` wrote";
  return "";
}

// What the trace is: `eamos verify --trace` says in its header that it holds a verification's
// worst path (which path, how many violations), and the page says so instead of a run's outcome.
void add_run_kind(const monitor::LoadedTrace& trace, nlohmann::json& view) {
  if (!trace.header || !trace.header->contains("run")) return;
  for (const char* key : {"run", "path", "paths", "violations"})
    if (trace.header->contains(key)) view[key] = (*trace.header)[key];
}

}  // namespace

void MonitorHold::wait_for_signal() {
  std::unique_lock<std::mutex> lock(mutex);
  signalled.wait(lock, [this] { return interrupted; });
}

bool MonitorHold::was_interrupted() {
  std::lock_guard<std::mutex> lock(mutex);
  return interrupted;
}

void MonitorHold::signal() {
  {
    std::lock_guard<std::mutex> lock(mutex);
    interrupted = true;
  }
  signalled.notify_all();
}

bool start_monitor(monitor::MonitorServer& server, const std::string& at, const nlohmann::json& view,
                   const std::string& option) {
  monitor::Endpoint endpoint;
  std::string error;
  if (!monitor::parse_endpoint(at, endpoint, error)) {
    std::cerr << error_prefix() << option << " " << error << "\n";
    return false;
  }
  server.set_mission(view.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  if (!server.start(endpoint, error)) {
    std::cerr << error_prefix() << "" << error << "\n";
    return false;
  }
  return true;
}

nlohmann::json live_view(const graph::Compilation& c, const std::string& mission, const std::string& fleet) {
  monitor::ViewInput in;
  in.mission_name = mission;
  in.fleet_text = fleet.empty() ? "" : read_text(fleet);
  in.live = true;
  std::string warnings;
  nlohmann::json view = monitor::mission_view(c, in, dot_renderer(), warnings);
  if (!warnings.empty()) std::cerr << "eamos: warning: " << warnings;
  return view;
}

// A deployment names its mission's source file and hash: when that file still compiles to
// the same hash, the page shows its graphs and text; otherwise the lanes only.
nlohmann::json launch_view(const std::string& dir) {
  monitor::ViewInput in;
  in.mission_name = dir;
  in.live = true;
  deploy::DeploymentManifest manifest;
  std::string error;
  if (!deploy::read_manifest(dir, manifest, error) || manifest.source.empty())
    return monitor::bare_view(in, "the deployment names no mission source: lanes only");
  std::string source = manifest.source;
  graph::Compilation c;
  Diagnostics diags;
  if (!graph::compile_file(source, "", diags, c) || deploy::mission_hash(c) != manifest.mission_hash)
    return monitor::bare_view(in, "'" + source + "' is not the deployed mission any more (or needs its fleet): lanes only");
  in.mission_name = source;
  std::string warnings;
  nlohmann::json view = monitor::mission_view(c, in, dot_renderer(), warnings);
  if (!warnings.empty()) std::cerr << "eamos: warning: " << warnings;
  return view;
}

int cmd_monitor(const MonitorCommandOptions& m) {
  MonitorHold hold;
  SignalWatch signals([&hold](const char* name) {
    std::fprintf(stderr, "eamos monitor: interrupted (%s): stopping\n", name);
    hold.signal();
  });
  // The address first: a mistyped one is said before a long trace is read.
  std::string at = m.host + ":" + std::to_string(m.port), error;
  monitor::Endpoint endpoint;
  if (!monitor::parse_endpoint(at, endpoint, error)) {
    std::cerr << "eamos: error: --host " << error << "\n";
    return 1;
  }
  // Read twice (its first line, then the whole): a regular file only.
  if (std::string why = diag::why_not_readable(m.trace, diag::Pipes::refused); !why.empty()) {
    std::cerr << error_prefix() << "cannot read trace '" << m.trace << "': " << why
              << "; give the file `eamos run --trace` wrote\n";
    return 1;
  }
  std::ifstream in(m.trace, std::ios::binary);
  if (!in) {
    std::cerr << error_prefix() << "cannot read trace '" << m.trace << "'; give the file `eamos run --trace` wrote\n";
    return 1;
  }
  if (std::string why = not_a_trace(m.trace); !why.empty()) {
    std::cerr << error_prefix() << why << "\n";
    return 1;
  }
  monitor::LoadedTrace trace = monitor::read_trace(m.trace, in);
  for (const auto& w : trace.warnings) std::cerr << w << "\n";
  if (!trace.errors.empty()) {
    for (const auto& e : trace.errors) std::cerr << e << "\n";
    std::cerr << "eamos monitor: the trace has errors; nothing to replay\n";
    return 1;
  }
  nlohmann::json view;
  if (!replay_view(m, trace, view)) return 1;
  add_run_kind(trace, view);
  monitor::MonitorServer server;
  if (!start_monitor(server, at, view, "--host")) return 1;
  for (auto& e : trace.events) server.append(std::move(e));
  server.finish();
  std::cout << "eamos monitor: replaying " << m.trace << " (" << trace.events.size() << " events) at "
            << server.url() << "\nopen it in a browser; Ctrl-C stops\n" << std::flush;
  hold.wait_for_signal();
  return 0;
}

}  // namespace eamos::cli
