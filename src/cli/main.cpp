// eamos: the command line. One function per subcommand declares its options into one
// Options; main parses, checks the output paths, and hands over to the chosen command.
#include <CLI/CLI.hpp>

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "cli/arguments.h"
#include "cli/commands.h"
#include "cli/heap_tunables.h"
#include "launch/stop_signals.h"
#include "lsp/server.h"
#include "security/mission_keys.h"
#include "version.h"

namespace {

void add_common(CLI::App* cmd, eamos::cli::CommonOptions& o) {
  cmd->add_option("mission", o.mission, "Mission file (.eamos)")->required()->check(eamos::cli::existing_file("a mission file"));
  cmd->add_option("--fleet", o.fleet, "Fleet file (YAML): drone types and per-drone settings")
      ->check(eamos::cli::existing_file("a fleet file"));
  cmd->add_option("--max-errors", o.max_errors, "Stop listing errors after N (0 = all)")
      ->default_val(200);
  cmd->add_flag("--werror", o.werror, "Treat warnings as errors");
  cmd->add_flag("-q,--quiet", o.quiet, "Do not print warnings");
}

void add_dds(CLI::App* cmd, eamos::transport::DdsOptions& d) {
  cmd->add_option("--domain", d.domain, "DDS domain id (0-230); missions on one domain ignore each other")
      ->default_val(0)->check(eamos::cli::whole_number(0, 230));
  cmd->add_option("--interface", d.interface,
                  "Network interface name or address for DDS (default: loopback only, config/cyclonedds-loopback.xml)");
  cmd->add_option("--dds-config", d.config_file, "A Cyclone DDS XML configuration to use instead")
      ->check(eamos::cli::existing_file("a DDS configuration"));
  cmd->add_option("--liveliness-timeout", d.lease_s,
                  "Seconds without liveliness after which a drone is lost and the mission fails")
      ->default_val(2.0)->check(eamos::cli::positive());
}

void add_report(CLI::App* cmd, eamos::cli::RunCommandOptions& r) {
  cmd->add_option("--trace", r.trace, "Write the trace as JSON Lines to this file");
  cmd->add_option("--summary", r.summary, "Write the summary JSON to this file");
  cmd->add_option("--plot", r.plot, "Draw the run (tracks and action timeline) as SVG to this file");
  cmd->add_option("--monitor", r.monitor,
                  "Serve the running mission live in a browser at [HOST:]PORT (default host 127.0.0.1; "
                  "port 0: any free one); the URL is printed, and the page stays up after the end until Ctrl-C");
  cmd->add_option("--telemetry-hz", r.telemetry_hz,
                  "Telemetry samples per drone per mission second in the trace (0: none)")
      ->default_val(5.0)->check(eamos::cli::number_between(0.0, 100.0));
}

void add_security(CLI::App* cmd, eamos::cli::SecurityOptions& s) {
  cmd->add_option("--keys", s.keys_dir,
                  "Folder with the identity and permissions CAs that sign the mission's DDS Security credentials "
                  "(made there when it has none; default: fresh CAs per compilation, their keys thrown away)");
  cmd->add_option("--valid-days", s.valid_days, "Days the mission's credentials are valid")
      ->default_val(30)->check(eamos::cli::whole_number(1, 3650));
  cmd->add_flag("--insecure", s.insecure,
                "No DDS Security: anyone on the network can command the drones (experiments only)");
}

void add_latency(CLI::App* cmd, eamos::launch::LaunchOptions& l, const std::string& prefix) {
  cmd->add_option("--trigger-latency-warn", l.latency_warn_s,
                  prefix + "Warn for each trigger or cancel between drones received more than this many mission "
                           "seconds after it was sent")
      ->default_val(eamos::dex::kDefaultLatencyWarnS)->check(eamos::cli::positive());
  cmd->add_option("--max-trigger-latency", l.max_trigger_latency_s,
                  prefix + "Fail the mission (every drone's failsafe) when a trigger or cancel between drones is "
                           "received more than this many mission seconds after it was sent (default: no bound)")
      ->check(eamos::cli::positive());
}

/// Every subcommand's options, as the command line sets them.
struct Options {
  std::string color = "auto";
  std::string log_level;
  std::string diagnostics_format = "text";
  eamos::cli::CommonOptions common;  ///< the mission and fleet of check, compile, graph, stats, run, verify
  bool list_caps = false;
  std::string out_dir;
  eamos::cli::SecurityOptions security;  ///< compile's, and run --distributed's
  eamos::deploy::PackageOptions package;
  bool packaged = false;
  std::string kind = "meg", drone, format = "dot", graph_out;
  std::string stats_out;
  eamos::cli::RunCommandOptions run;
  bool distributed = false;
  eamos::cli::VerifyCommandOptions verify;
  eamos::launch::LaunchOptions launch;  ///< launch's, and run --distributed's
  eamos::cli::RunCommandOptions launch_report;
  eamos::launch::DexProcessOptions dex;
  eamos::cli::MonitorCommandOptions monitor;
  long long nodes = 5000;
  int work_per_step = 4;
  int drones = 20;
  unsigned seed = 1;
  std::string gen_out;
  std::string shape = "squads";
  eamos::cli::SimVehicleCommandOptions sim_vehicle;
  eamos::lsp::ServerOptions lsp;
  bool lsp_stdio = true;
};

/// The subcommands, to tell which one the command line chose.
struct Commands {
  CLI::App *check, *compile, *graph, *stats, *run, *verify, *launch, *dex, *monitor, *gen, *sim_vehicle, *lsp;
};

void add_global(CLI::App& app, Options& o) {
  app.set_version_flag("--version", std::string("eamos ") + EAMOS_VERSION);
  app.require_subcommand(1);
  // Options of eamos itself (colour, diagnostics format) may also come after the command.
  app.fallthrough();
  app.add_option("--color", o.color,
                 "Colour in diagnostics: auto (on a terminal, unless NO_COLOR is set), always, never")
      ->check(eamos::cli::one_of({"auto", "always", "never"}));
  app.add_option("--log-level", o.log_level,
                 "Which messages of eamos's parts (links, transport, executor) reach standard error: error, warning, "
                 "info (default, or $EAMOS_LOG_LEVEL) or debug; the DEX processes a launch starts inherit it")
      ->check(eamos::cli::one_of({"error", "warning", "info", "debug"}));
  app.add_option("--diagnostics-format", o.diagnostics_format,
                 "How errors and warnings of a mission are printed: text (GCC style), json, or sarif (SARIF 2.1.0); "
                 "`check` prints json and sarif on standard output, other commands on standard error")
      ->check(eamos::cli::one_of({"text", "json", "sarif"}));
}

CLI::App* add_check(CLI::App& app, Options& o) {
  auto* check = app.add_subcommand("check", "Check a mission and print every error and warning");
  add_common(check, o.common);
  check->add_flag("--list-capabilities", o.list_caps, "Also list each drone's actions and properties");
  return check;
}

CLI::App* add_compile(CLI::App& app, Options& o) {
  auto* compile = app.add_subcommand("compile", "Compile a mission into per-drone mission files and deployment folders");
  add_common(compile, o.common);
  compile->add_option("-o,--output", o.out_dir, "Output folder")->required();
  add_security(compile, o.security);
  auto* package_flag = compile->add_flag(
      "--package", o.packaged, "Also write what each drone's companion computer needs to run its DEX as a systemd service: "
                   "cyclonedds.xml for a real network, dex.env, eamos-dex@.service, DEPLOY.txt (docs/deploy.md)");
  compile->add_option("--interface", o.package.interface,
                      "With --package: the network interface the drones' DDS uses, written into each dex.env "
                      "(default: left for you to set there)")
      ->needs(package_flag);
  compile->add_option("--domain", o.package.domain, "With --package: the DDS domain id (0-230) every DEX joins")
      ->default_val(0)->check(eamos::cli::whole_number(0, 230))->needs(package_flag);
  return compile;
}

CLI::App* add_graph(CLI::App& app, Options& o) {
  auto* graph = app.add_subcommand("graph", "Write the AMT, MEG or a drone's MDG as DOT, JSON or SVG");
  add_common(graph, o.common);
  graph->add_option("--kind", o.kind, "amt | meg | mdg")->check(eamos::cli::one_of({"amt", "meg", "mdg"}));
  graph->add_option("--drone", o.drone, "Drone whose MDG to write (with --kind mdg)");
  graph->add_option("--format", o.format, "dot | json | svg")->check(eamos::cli::one_of({"dot", "json", "svg"}));
  graph->add_option("-o,--output", o.graph_out, "Output file (default: standard output)");
  return graph;
}

CLI::App* add_stats(CLI::App& app, Options& o) {
  auto* stats = app.add_subcommand("stats", "Nodes and arcs per graph and per drone, as JSON");
  add_common(stats, o.common);
  stats->add_option("-o,--output", o.stats_out, "Output file (default: standard output)");
  return stats;
}

CLI::App* add_run(CLI::App& app, Options& o) {
  auto* run = app.add_subcommand("run", "Compile and fly a mission in the built-in simulator; exit 0 only when it completed");
  add_common(run, o.common);
  add_report(run, o.run);
  auto* realtime = run->add_flag("--realtime", o.run.realtime, "Run in real time instead of virtual time");
  run->add_option("--speed", o.run.speed, "Real time scaled by X (2 = twice as fast)")
      ->check(eamos::cli::positive())->excludes(realtime);
  run->add_option("--time-limit", o.run.time_limit, "Fail a mission still running after this many mission seconds")
      ->check(eamos::cli::positive());
  return run;
}

// `run --distributed`: the options of `launch` it takes, each marked so in the help.
void add_run_distributed(CLI::App* run, Options& o) {
  CLI::Option* distributed = run->add_flag("--distributed", o.distributed,
                                           "One DEX process per drone over Cyclone DDS, as `eamos launch` (real time)");
  std::size_t before = run->get_options().size();
  run->add_option("--deploy-dir", o.launch.dir, "With --distributed: where to write the deployment (default: a temporary folder)");
  run->add_option("--barrier-timeout", o.launch.barrier_timeout_s, "With --distributed: seconds to wait for every DEX to be ready")
      ->check(eamos::cli::positive());
  run->add_option("--final-state-timeout", o.launch.final_state_timeout_s,
                  "With --distributed: seconds to wait for a lost drone to report its final state (then: unknown)")
      ->check(eamos::cli::non_negative());
  add_dds(run, o.launch.dds);
  add_latency(run, o.launch, "With --distributed: ");
  add_security(run, o.security);
  // Without --distributed they would be accepted and ignored: a user who asked for a deployment
  // folder or a DDS domain must learn that the run used neither.
  std::vector<CLI::Option*> options = run->get_options();
  for (std::size_t i = before; i < options.size(); ++i) options[i]->needs(distributed);
}

CLI::App* add_verify(CLI::App& app, Options& o) {
  auto* verify = app.add_subcommand("verify", "Fly every explored path of a mission in the simulator and report each broken rule (separation, geofence, battery, ...) at its action; exit 1 on any");
  add_common(verify, o.common);
  eamos::cli::VerifyCommandOptions& v = o.verify;
  verify->add_option("--paths", v.paths, "Fly at most N paths (combinations of condition outcomes and timings)")
      ->check(eamos::cli::whole_number(1, 1000000));
  verify->add_flag("--jitter", v.jitter, "Also fly each path with drones 10 % slower and faster");
  verify->add_option("--time-limit", v.time_limit, "A path still running after this many mission seconds never ends")
      ->check(eamos::cli::positive());
  verify->add_flag("--json", v.json, "Print the report as JSON");
  verify->add_option("--plot", v.plot, "Draw the first path with the violations marked in red as SVG to this file");
  verify->add_option("--trace", v.trace, "Write the trace of the path --plot draws, with a violation event per broken rule, as JSON Lines to this file (`eamos monitor` replays it)");
  return verify;
}

CLI::App* add_launch(CLI::App& app, Options& o) {
  auto* launch = app.add_subcommand("launch", "Run a deployment folder as one DEX process per drone over Cyclone DDS, with a ground process that starts them together and collects their traces");
  eamos::launch::LaunchOptions& l = o.launch;
  launch->add_option("deployment", l.dir, "Deployment folder written by `eamos compile -o`")
      ->required()->check(eamos::cli::existing_folder("a deployment folder"));
  add_report(launch, o.launch_report);
  launch->add_option("--speed", l.speed, "Mission time runs X times as fast as the wall clock (simulated drones only)")
      ->check(eamos::cli::positive());
  launch->add_option("--time-limit", l.time_limit_s, "Fail a mission still running after this many mission seconds")
      ->check(eamos::cli::positive());
  launch->add_option("--barrier-timeout", l.barrier_timeout_s,
                     "Seconds to wait for every DEX to be ready (default: 30, plus 0.5 per drone beyond 20; with DDS "
                     "Security at most 85)")
      ->check(eamos::cli::positive());
  launch->add_option("--start-wave", l.start_wave,
                     "Start this many DEX processes at once, the next ones when the ground has heard from them "
                     "(default: the whole fleet up to 10 drones with DDS Security, 25 without; then waves of that size, "
                     "with DDS Security beyond 50 drones of 5)")
      ->check(eamos::cli::whole_number(1, 100000));
  launch->add_option("--state-rate", l.state_rate_hz,
                     "Each DEX publishes its drone's state to the others at most this many times a wall second "
                     "(default: 20 up to 20 drones, then 20 * (20 / drones)^2, at least 1)")
      ->check(eamos::cli::positive());
  launch->add_option("--drones", l.local, "Start only these drones here; the others run their DEX elsewhere")
      ->delimiter(',');
  launch->add_flag("--remote-only", l.remote_only,
                   "Start no DEX here: every drone's DEX runs elsewhere (`eamos dex` on the drone)")
      ->excludes("--drones");
  launch->add_option("--final-state-timeout", l.final_state_timeout_s,
                     "Seconds to wait for a lost drone to come back and report its final state (then: unknown)")
      ->check(eamos::cli::non_negative());
  add_dds(launch, l.dds);
  add_latency(launch, l, "");
  launch->add_flag("--insecure", l.insecure,
                   "Fly without DDS Security, even when the deployment has credentials (experiments only)");
  return launch;
}

CLI::App* add_dex(CLI::App& app, Options& o) {
  auto* dexcmd = app.add_subcommand("dex", "Run one drone's DEX from its deployment folder (the deployment package's entry point)");
  eamos::launch::DexProcessOptions& d = o.dex;
  dexcmd->add_option("folder", d.folder, "The drone's deployment folder (DIR/<drone>)")
      ->required()->check(eamos::cli::existing_folder("a drone's deployment folder"));
  dexcmd->add_option("--speed", d.speed, "Mission time runs X times as fast as the wall clock; must match the ground's")
      ->check(eamos::cli::positive());
  dexcmd->add_option("--time-limit", d.time_limit_s, "Fail a mission still running after this many mission seconds")
      ->check(eamos::cli::positive());
  dexcmd->add_option("--start-timeout", d.start_timeout_s, "Give up when no start came within this many seconds (default: wait)")
      ->check(eamos::cli::non_negative());
  dexcmd->add_option("--ready-timeout", d.unready_limit_s,
                     "With DDS Security: leave (exit 1) when not every other drone was heard from within this many "
                     "seconds of joining DDS, before Cyclone DDS gives its handshakes up (default and most: 90)")
      ->check(eamos::cli::number_between(0.1, eamos::launch::kSecureUnreadyLimitS));
  dexcmd->add_option("--later-drones", d.later_drones,
                     "Drones whose DEX starts after this one (set by `eamos launch` for its later waves): "
                     "--ready-timeout does not wait for them, their own DEX answers for those handshakes")
      ->delimiter(',');
  dexcmd->add_option("--state-rate", d.state_rate_hz,
                     "Publish this drone's state to the other drones at most this many times a wall second, "
                     "20 or more: at every change (default: 20 up to 20 drones, then 20 * (20 / drones)^2, at least 1)")
      ->check(eamos::cli::positive());
  dexcmd->add_option("--trace", d.trace_file, "Also write this drone's trace as JSON Lines to this file");
  dexcmd->add_option("--launch-id", d.launch_id,
                     "Take a start only from the `eamos launch` with this id (set by the launch that starts the DEX)");
  add_dds(dexcmd, d.dds);
  dexcmd->add_option("--max-trigger-latency", d.max_trigger_latency_s,
                     "Fail the mission (failsafe, ABORT to every drone) when a trigger or cancel reaches this drone "
                     "more than this many mission seconds after it was sent (default: no bound)")
      ->check(eamos::cli::positive());
  dexcmd->add_flag("--insecure", d.insecure,
                   "Fly without DDS Security, even when the folder has credentials (experiments only)");
  return dexcmd;
}

CLI::App* add_monitor(CLI::App& app, Options& o) {
  auto* monitor = app.add_subcommand("monitor", "Replay a finished mission's trace in the browser (the URL is printed)");
  eamos::cli::MonitorCommandOptions& m = o.monitor;
  monitor->add_option("trace", m.trace, "The trace (JSON Lines) `eamos run --trace` wrote")
      ->required()->check(eamos::cli::existing_file("a trace"));
  monitor->add_option("--port", m.port, "Port to serve at (0: any free one)")
      ->default_val(8080)->check(eamos::cli::whole_number(0, 65535));
  monitor->add_option("--host", m.host, "Numeric IP address to serve at (0.0.0.0: every interface; default 127.0.0.1, this machine only)")
      ->default_val("127.0.0.1");
  auto* monitor_mission = monitor->add_option("--mission", m.mission,
                      "The mission, for a trace that does not carry it (an older trace): adds the graphs and the text")
      ->check(eamos::cli::existing_file("a mission file"));
  monitor->add_option("--fleet", m.fleet, "The fleet file, with --mission")
      ->check(eamos::cli::existing_file("a fleet file"))->needs(monitor_mission);
  return monitor;
}

CLI::App* add_gen_stress(CLI::App& app, Options& o) {
  auto* gen = app.add_subcommand("gen-stress", "Generate a large valid mission for scaling tests");
  gen->add_option("--shape", o.shape,
                  "squads: squads of ten, each its own barriers; show: every drone in every PAR; cross: squads that "
                  "wait on, branch on and fly to other squads' drones")
      ->check(eamos::cli::one_of({"squads", "show", "cross"}));
  gen->add_option("--work", o.work_per_step, "Work items per drone between two barriers")->check(eamos::cli::whole_number(1, 1000));
  gen->add_option("--nodes", o.nodes, "Approximate number of MEG nodes")->check(eamos::cli::whole_number(10, 50'000'000));
  gen->add_option("--drones", o.drones, "Number of drones")->check(eamos::cli::whole_number(1, 100000));
  gen->add_option("--seed", o.seed, "Seed of the generator (same seed, same mission)");
  gen->add_option("-o,--output", o.gen_out, "Output file (default: standard output)");
  return gen;
}

CLI::App* add_sim_vehicle(CLI::App& app, Options& o) {
  auto* simv = app.add_subcommand("sim-vehicle", "Run a PX4-like MAVLink vehicle on the built-in simulator (for the mavlink adapter)");
  eamos::cli::SimVehicleCommandOptions& v = o.sim_vehicle;
  auto* udp = simv->add_option("--udp", v.udp_port, "Send to 127.0.0.1:PORT, like PX4 SITL (whose instance i sends to 14540 + i)")
      ->check(eamos::cli::whole_number(1, 65535));
  simv->add_option("--gcs", v.ground_station,
                   "Also stream to a ground station so QGroundControl shows the vehicle, e.g. udpout://127.0.0.1:14550");
  simv->add_option("--connection", v.connection, "Any link URL instead: udp://:PORT, udpout://HOST:PORT, tcp://HOST:PORT or serial://DEVICE:RATE")
      ->excludes(udp);
  simv->add_option("--sysid", v.sysid, "MAVLink system id")->check(eamos::cli::whole_number(1, 255));
  simv->add_option("--autopilot", v.autopilot, "Whose modes and rules to play: px4 (OFFBOARD) or ardupilot (Copter, GUIDED)")
      ->check(eamos::cli::one_of({"px4", "ardupilot"}));
  simv->add_option("--east", v.east, "Stand this many metres east of 47.397742 N, 8.545594 E (PX4 SITL's home); "
                   "give each vehicle its fleet home's x")->check(eamos::cli::number_between(-100000.0, 100000.0));
  simv->add_option("--north", v.north, "Stand this many metres north of it; the fleet home's y")
      ->check(eamos::cli::number_between(-100000.0, 100000.0));
  simv->add_option("--battery", v.battery, "Charge at start, %; 0 makes it refuse to arm")->check(eamos::cli::number_between(0.0, 100.0));
  simv->add_option("--speed", v.speed, "Mission time runs X times as fast as the wall clock; the adapter's run must use the same")
      ->check(eamos::cli::positive());
  simv->add_option("--duration", v.duration, "Stop after this many mission seconds (default: until interrupted)")
      ->check(eamos::cli::non_negative());
  return simv;
}

CLI::App* add_lsp(CLI::App& app, Options& o) {
  auto* lsp = app.add_subcommand("lsp", "Serve the Language Server Protocol on standard input and output, for editors "
                                       "(docs/editors.md): diagnostics as you type, hover, go-to-definition, completion, outline");
  lsp->add_option("--fleet", o.lsp.fleet,
                  "Fleet file (YAML) to check every mission against, as `eamos check --fleet`; the client's "
                  "initializationOptions {\"fleet\": PATH} replace it");
  lsp->add_flag("--stdio", o.lsp_stdio, "Talk over standard input and output (the only transport; editors pass it)");
  return lsp;
}

/// Every subcommand on `app`, in the order `eamos --help` lists them.
Commands add_commands(CLI::App& app, Options& o) {
  Commands c{};
  c.check = add_check(app, o);
  c.compile = add_compile(app, o);
  c.graph = add_graph(app, o);
  c.stats = add_stats(app, o);
  c.run = add_run(app, o);
  c.verify = add_verify(app, o);
  add_run_distributed(c.run, o);
  c.launch = add_launch(app, o);
  c.dex = add_dex(app, o);
  c.monitor = add_monitor(app, o);
  c.gen = add_gen_stress(app, o);
  c.sim_vehicle = add_sim_vehicle(app, o);
  c.lsp = add_lsp(app, o);
  return c;
}

/// Every file the chosen command writes, checked before it compiles or flies anything: a
/// run must not end in "cannot write" after the flight. False (said on stderr) on the first
/// command whose outputs are unusable.
bool outputs_usable(const Commands& c, const std::vector<std::string>& args, const Options& o) {
  auto out = [](CLI::App* sub, const char* name, bool folder = false) {
    return eamos::cli::OutputPath{sub->get_option_no_throw(name), folder};
  };
  std::vector<std::pair<CLI::App*, std::vector<eamos::cli::OutputPath>>> outputs = {
      {c.compile, {out(c.compile, "--output", true)}},
      {c.graph, {out(c.graph, "--output")}},
      {c.stats, {out(c.stats, "--output")}},
      {c.gen, {out(c.gen, "--output")}},
      {c.run, {out(c.run, "--trace"), out(c.run, "--summary"), out(c.run, "--plot"), out(c.run, "--deploy-dir", true)}},
      {c.verify, {out(c.verify, "--plot"), out(c.verify, "--trace")}},
      {c.launch, {out(c.launch, "--trace"), out(c.launch, "--summary"), out(c.launch, "--plot")}},
      {c.dex, {out(c.dex, "--trace")}},
  };
  std::vector<std::string> inputs = {o.common.mission, o.common.fleet, o.monitor.trace, o.monitor.mission};
  for (const auto& [sub, paths] : outputs) {
    if (!*sub) continue;
    if (std::string bad = eamos::cli::check_outputs(*sub, args, paths, inputs); !bad.empty()) {
      std::cerr << bad;
      return false;
    }
  }
  return true;
}

/// Puts the heap tunables (cli/heap_tunables.h) in the environment for the program this one
/// starts or becomes; false, and nothing changed, when the user's GLIBC_TUNABLES already
/// chooses huge pages or not.
bool ask_malloc_for_huge_pages() {
  const char* user = std::getenv("GLIBC_TUNABLES");
  std::optional<std::string> tunables = eamos::cli::heap_tunables(user ? user : "");
  return tunables && ::setenv("GLIBC_TUNABLES", tunables->c_str(), 1) == 0;
}

#ifdef EAMOS_FLY_ELSEWHERE
/// A helper program (eamos-fly, eamos-credentials): next to this program (the build tree, or
/// all in bin/), else in ../libexec/eamos/ (the install tree and the Debian package).
std::string helper_program(const char* name) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path self = fs::read_symlink("/proc/self/exe", ec);
  // Never a path relative to the working directory: that would run whatever lies there.
  if (ec || !self.is_absolute()) return std::string("/proc/self/exe/../") + name;
  fs::path beside = self.parent_path() / name;
  if (fs::exists(beside, ec)) return beside.string();
  return (self.parent_path().parent_path() / "libexec" / "eamos" / name).string();
}

std::string fly_program() { return helper_program("eamos-fly"); }

/// The compile's last step: this process becomes eamos-credentials (the same pid, so a
/// caller waits for, and measures, one process), which makes the credentials and prints
/// `end.done`. `eamos` itself never maps libcrypto.
int exec_credentials(const eamos::cli::CompileEnding& end) {
  std::string program = helper_program("eamos-credentials");
  std::string days = std::to_string(end.security.valid_days);
  const char* color = eamos::cli::output_style().color_stderr ? "always" : "never";
  std::vector<const char*> argv = {program.c_str(), "--deploy-dir", end.out_dir.c_str(), "--mission-hash",
                                   end.hash.c_str(), "--valid-days", days.c_str(), "--color", color,
                                   "--done", end.done.c_str()};
  if (!end.security.keys_dir.empty()) argv.insert(argv.end(), {"--keys", end.security.keys_dir.c_str()});
  argv.push_back("--");
  for (const std::string& d : end.drones) argv.push_back(d.c_str());
  argv.push_back(nullptr);
  std::cout.flush();
  std::fflush(nullptr);
  ::execv(program.c_str(), const_cast<char* const*>(argv.data()));
  int why = errno;
  // No other compilation's credentials may stay beside these mission files.
  eamos::security::remove_mission_keys(end.out_dir, end.drones);
  std::cerr << eamos::cli::error_prefix() << "cannot start " << program << " to make the DDS Security credentials: "
            << std::strerror(why) << "; the installation is incomplete (reinstall eamos)\n";
  return 1;
}

/// The commands that fly or serve (run, verify, launch, dex, sim-vehicle, monitor) live in
/// eamos-fly, which links Cyclone DDS, civetweb and the MAVLink stack. This `eamos` links none
/// of them, so check, compile and the other commands start without loading them
/// (docs/performance.md); a flying command replaces it with eamos-fly: the same pid, terminal
/// and arguments.
int fly(const Commands& c, Options& o, char** argv) {
  std::string program = fly_program();
  argv[0] = program.data();
  // `run` in one process holds the whole fleet (some 200 MB for 1,000 drones), and `verify`
  // flies it path after path; the processes of a distributed run are many and small, and
  // the long-lived ones (dex, launch, monitor) hand back what they free: they keep the default.
  if ((*c.run && !o.distributed) || *c.verify) ask_malloc_for_huge_pages();
  ::execv(program.c_str(), argv);
  std::cerr << eamos::cli::error_prefix() << "cannot start " << program << ": " << std::strerror(errno)
            << "; the installation is incomplete (reinstall eamos)\n";
  return 1;
}
constexpr eamos::cli::CompileFinisher kFinishCompile{exec_credentials, true};
#else
int fly(const Commands& c, Options& o, char**) {
  // A reader of the log that goes away (`| head`, a pager closed) or Ctrl-Z must not end or
  // suspend a flight.
  eamos::launch::keep_flying_through_the_terminal();
  if (*c.run && o.distributed) {
    o.launch.speed = o.run.speed > 0 ? o.run.speed : 1.0;
    o.launch.time_limit_s = o.run.time_limit;
    return eamos::cli::cmd_run_distributed(o.common, o.run, o.launch, o.security);
  }
  if (*c.run) return eamos::cli::cmd_run(o.common, o.run);
  if (*c.verify) return eamos::cli::cmd_verify(o.common, o.verify);
  if (*c.launch) return eamos::cli::cmd_launch(o.launch, o.launch_report);
  if (*c.dex) return eamos::cli::cmd_dex(o.dex);
  if (*c.sim_vehicle) return eamos::cli::cmd_sim_vehicle(o.sim_vehicle);
  if (*c.monitor) return eamos::cli::cmd_monitor(o.monitor);
  return 1;
}
constexpr eamos::cli::CompileFinisher kFinishCompile{eamos::cli::finish_in_process, false};
#endif

/// Sources from this size on (about 40,000 statements) are compiled on huge pages; below it
/// the restart's cost and the 2 MiB pages' rounding are not worth it (5,000 statements:
/// no CPU to take, up to 1 MB more peak memory).
constexpr std::uintmax_t kHugePagesFrom = std::uintmax_t{1} << 20;

/// A large compile first-touches hundreds of MB, and in 4 KiB pages each is a page fault:
/// most of the kernel's share of the compile (docs/performance.md, "Fleets of a thousand").
/// A compile of a large source therefore starts this program again on huge pages. Returns
/// only when the compile goes on in this process.
void restart_on_huge_pages(const std::string& mission, char** argv) {
  std::error_code ec;
  std::uintmax_t size = std::filesystem::file_size(mission, ec);
  if (ec || size < kHugePagesFrom || !ask_malloc_for_huge_pages()) return;
  std::cout.flush();
  std::fflush(nullptr);
  ::execv("/proc/self/exe", argv);  // on failure the compile goes on here, on small pages
}

/// Runs the command the line chose; its exit status.
int dispatch(const Commands& c, Options& o, char** argv) {
  if (*c.check) return eamos::cli::cmd_check(o.common, o.list_caps);
  if (*c.compile) {
    restart_on_huge_pages(o.common.mission, argv);
    return eamos::cli::cmd_compile(o.common, o.out_dir, o.security, o.packaged ? &o.package : nullptr, kFinishCompile);
  }
  if (*c.graph) return eamos::cli::cmd_graph(o.common, o.kind, o.drone, o.format, o.graph_out);
  if (*c.stats) return eamos::cli::cmd_stats(o.common, o.stats_out);
  if (*c.gen) return eamos::cli::cmd_gen_stress(o.shape, o.nodes, o.drones, o.work_per_step, o.seed, o.gen_out);
  if (*c.lsp) return eamos::lsp::serve_stdio(o.lsp);
  return fly(c, o, argv);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"eamos — write a multidrone mission as a short program; every drone runs its part.",
               "eamos"};
  Options o;
  add_global(app, o);
  Commands c = add_commands(app, o);

  std::vector<std::string> args(argv + 1, argv + argc);
  eamos::cli::OutputStyle& style = eamos::cli::output_style();
  style.color_stderr = eamos::cli::use_color(eamos::cli::color_argument(args), STDERR_FILENO);
  if (std::string unknown = eamos::cli::unknown_names(app, args); !unknown.empty()) {
    std::cerr << unknown;
    return 1;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << eamos::cli::explain_parse_error(app, args, e);
    return 1;
  }
#ifdef EAMOS_FLY_ELSEWHERE
  // Handed over as parsed, before this process checks or writes anything: eamos-fly does it all.
  if (*c.run || *c.verify || *c.launch || *c.dex || *c.sim_vehicle || *c.monitor) return fly(c, o, argv);
#endif
  style.color_stderr = eamos::cli::use_color(o.color, STDERR_FILENO);
  style.diagnostics = o.diagnostics_format;
  eamos::cli::apply_log_level(o.log_level);
  if (!outputs_usable(c, args, o)) return 1;

  // A flight's live log goes out line by line also into a pipe (`| tee log`): what a person
  // watches is now, not a buffer later, and a killed process loses at most half a line.
  // `eamos run` on virtual time into a file (run_log_in_blocks) is the exception: its
  // whole flight takes seconds, and a Ctrl-C or SIGTERM lands the drones and flushes it
  // (a second one, which exits at once, leaves the last block unwritten).
  bool blocks = *c.run && !o.distributed && eamos::cli::run_log_in_blocks(o.run);
  if ((*c.run || *c.launch || *c.dex || *c.sim_vehicle || *c.monitor) && !blocks)
    std::setvbuf(stdout, nullptr, _IOLBF, BUFSIZ);
  // Blocks of 64 KiB rather than stdio's 4 KiB: a 1,000-drone run logs some 10 MB, and each
  // write is a system call. (glibc takes the size only with a buffer.)
  static char log_block[std::size_t{1} << 16];
  if (blocks) std::setvbuf(stdout, log_block, _IOFBF, sizeof log_block);
  try {
    return dispatch(c, o, argv);
  } catch (const std::exception& e) {
    std::cerr << eamos::cli::error_prefix() << e.what() << "\n";
    return 1;
  }
}
