// eamos: the command-line front of the Mission Compiler (and, later, of the DEX).
#include <CLI/CLI.hpp>

#include <unistd.h>

#include <cstdio>
#include <iostream>

#include "cli/arguments.h"
#include "cli/commands.h"
#include "lsp/server.h"
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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"eamos — write a multidrone mission as a short program; every drone runs its part.",
               "eamos"};
  app.set_version_flag("--version", std::string("eamos ") + EAMOS_VERSION);
  app.require_subcommand(1);
  // Options of eamos itself (colour, diagnostics format) may also come after the command.
  app.fallthrough();
  std::string color = "auto";
  app.add_option("--color", color,
                 "Colour in diagnostics: auto (on a terminal, unless NO_COLOR is set), always, never")
      ->check(eamos::cli::one_of({"auto", "always", "never"}));
  std::string diagnostics_format = "text";
  app.add_option("--diagnostics-format", diagnostics_format,
                 "How errors and warnings of a mission are printed: text (GCC style), json, or sarif (SARIF 2.1.0); "
                 "`check` prints json and sarif on standard output, other commands on standard error")
      ->check(eamos::cli::one_of({"text", "json", "sarif"}));

  eamos::cli::CommonOptions o;

  auto* check = app.add_subcommand("check", "Check a mission and print every error and warning");
  add_common(check, o);
  bool list_caps = false;
  check->add_flag("--list-capabilities", list_caps, "Also list each drone's actions and properties");

  auto* compile = app.add_subcommand("compile", "Compile a mission into per-drone mission files and deployment folders");
  add_common(compile, o);
  std::string out_dir;
  compile->add_option("-o,--output", out_dir, "Output folder")->required();
  eamos::cli::SecurityOptions security;
  add_security(compile, security);
  eamos::deploy::PackageOptions package;
  bool packaged = false;
  auto* package_flag = compile->add_flag(
      "--package", packaged, "Also write what each drone's companion computer needs to run its DEX as a systemd service: "
                   "cyclonedds.xml for a real network, dex.env, eamos-dex@.service, DEPLOY.txt (docs/deploy.md)");
  compile->add_option("--interface", package.interface,
                      "With --package: the network interface the drones' DDS uses, written into each dex.env "
                      "(default: left for you to set there)")
      ->needs(package_flag);
  compile->add_option("--domain", package.domain, "With --package: the DDS domain id (0-230) every DEX joins")
      ->default_val(0)->check(eamos::cli::whole_number(0, 230))->needs(package_flag);

  auto* graph = app.add_subcommand("graph", "Write the AMT, MEG or a drone's MDG as DOT, JSON or SVG");
  add_common(graph, o);
  std::string kind = "meg", drone, format = "dot", graph_out;
  graph->add_option("--kind", kind, "amt | meg | mdg")->check(eamos::cli::one_of({"amt", "meg", "mdg"}));
  graph->add_option("--drone", drone, "Drone whose MDG to write (with --kind mdg)");
  graph->add_option("--format", format, "dot | json | svg")->check(eamos::cli::one_of({"dot", "json", "svg"}));
  graph->add_option("-o,--output", graph_out, "Output file (default: standard output)");

  auto* stats = app.add_subcommand("stats", "Nodes and arcs per graph and per drone, as JSON");
  add_common(stats, o);
  std::string stats_out;
  stats->add_option("-o,--output", stats_out, "Output file (default: standard output)");

  auto* run = app.add_subcommand("run", "Compile and fly a mission in the built-in simulator; exit 0 only when it completed");
  add_common(run, o);
  eamos::cli::RunCommandOptions run_opts;
  add_report(run, run_opts);
  auto* realtime = run->add_flag("--realtime", run_opts.realtime, "Run in real time instead of virtual time");
  run->add_option("--speed", run_opts.speed, "Real time scaled by X (2 = twice as fast)")
      ->check(eamos::cli::positive())->excludes(realtime);
  run->add_option("--time-limit", run_opts.time_limit, "Fail a mission still running after this many mission seconds")
      ->check(eamos::cli::positive());

  auto* verify = app.add_subcommand("verify", "Fly every explored path of a mission in the simulator and report each broken rule (separation, geofence, battery, ...) at its action; exit 1 on any");
  add_common(verify, o);
  eamos::cli::VerifyCommandOptions verify_opts;
  verify->add_option("--paths", verify_opts.paths, "Fly at most N paths (combinations of condition outcomes and timings)")
      ->check(eamos::cli::whole_number(1, 1000000));
  verify->add_flag("--jitter", verify_opts.jitter, "Also fly each path with drones 10 % slower and faster");
  verify->add_option("--time-limit", verify_opts.time_limit, "A path still running after this many mission seconds never ends")
      ->check(eamos::cli::positive());
  verify->add_flag("--json", verify_opts.json, "Print the report as JSON");
  verify->add_option("--plot", verify_opts.plot, "Draw the first path with the violations marked in red as SVG to this file");
  verify->add_option("--trace", verify_opts.trace, "Write the trace of the path --plot draws, with a violation event per broken rule, as JSON Lines to this file (`eamos monitor` replays it)");

  bool distributed = false;
  eamos::launch::LaunchOptions launch_opts;
  run->add_flag("--distributed", distributed,
                "One DEX process per drone over Cyclone DDS, as `eamos launch` (real time)");
  run->add_option("--deploy-dir", launch_opts.dir, "With --distributed: where to write the deployment (default: a temporary folder)");
  run->add_option("--barrier-timeout", launch_opts.barrier_timeout_s, "With --distributed: seconds to wait for every DEX to be ready")
      ->check(eamos::cli::positive());
  run->add_option("--final-state-timeout", launch_opts.final_state_timeout_s,
                  "With --distributed: seconds to wait for a lost drone to report its final state (then: unknown)")
      ->check(eamos::cli::non_negative());
  add_dds(run, launch_opts.dds);
  add_latency(run, launch_opts, "With --distributed: ");
  add_security(run, security);

  auto* launch = app.add_subcommand("launch", "Run a deployment folder as one DEX process per drone over Cyclone DDS, with a ground process that starts them together and collects their traces");
  launch->add_option("deployment", launch_opts.dir, "Deployment folder written by `eamos compile -o`")
      ->required()->check(eamos::cli::existing_folder("a deployment folder"));
  eamos::cli::RunCommandOptions launch_report;
  add_report(launch, launch_report);
  launch->add_option("--speed", launch_opts.speed, "Mission time runs X times as fast as the wall clock (simulated drones only)")
      ->check(eamos::cli::positive());
  launch->add_option("--time-limit", launch_opts.time_limit_s, "Fail a mission still running after this many mission seconds")
      ->check(eamos::cli::positive());
  launch->add_option("--barrier-timeout", launch_opts.barrier_timeout_s, "Seconds to wait for every DEX to be ready")
      ->check(eamos::cli::positive());
  launch->add_option("--drones", launch_opts.local, "Start only these drones here; the others run their DEX elsewhere")
      ->delimiter(',');
  launch->add_flag("--remote-only", launch_opts.remote_only,
                   "Start no DEX here: every drone's DEX runs elsewhere (`eamos dex` on the drone)")
      ->excludes("--drones");
  launch->add_option("--final-state-timeout", launch_opts.final_state_timeout_s,
                     "Seconds to wait for a lost drone to come back and report its final state (then: unknown)")
      ->check(eamos::cli::non_negative());
  add_dds(launch, launch_opts.dds);
  add_latency(launch, launch_opts, "");
  launch->add_flag("--insecure", launch_opts.insecure,
                   "Fly without DDS Security, even when the deployment has credentials (experiments only)");

  auto* dexcmd = app.add_subcommand("dex", "Run one drone's DEX from its deployment folder (the deployment package's entry point)");
  eamos::launch::DexProcessOptions dex_opts;
  dexcmd->add_option("folder", dex_opts.folder, "The drone's deployment folder (DIR/<drone>)")
      ->required()->check(eamos::cli::existing_folder("a drone's deployment folder"));
  dexcmd->add_option("--speed", dex_opts.speed, "Mission time runs X times as fast as the wall clock; must match the ground's")
      ->check(eamos::cli::positive());
  dexcmd->add_option("--time-limit", dex_opts.time_limit_s, "Fail a mission still running after this many mission seconds")
      ->check(eamos::cli::positive());
  dexcmd->add_option("--start-timeout", dex_opts.start_timeout_s, "Give up when no start came within this many seconds (default: wait)")
      ->check(eamos::cli::non_negative());
  dexcmd->add_option("--trace", dex_opts.trace_file, "Also write this drone's trace as JSON Lines to this file");
  dexcmd->add_option("--launch-id", dex_opts.launch_id,
                     "Take a start only from the `eamos launch` with this id (set by the launch that starts the DEX)");
  add_dds(dexcmd, dex_opts.dds);
  dexcmd->add_option("--max-trigger-latency", dex_opts.max_trigger_latency_s,
                     "Fail the mission (failsafe, ABORT to every drone) when a trigger or cancel reaches this drone "
                     "more than this many mission seconds after it was sent (default: no bound)")
      ->check(eamos::cli::positive());
  dexcmd->add_flag("--insecure", dex_opts.insecure,
                   "Fly without DDS Security, even when the folder has credentials (experiments only)");

  auto* monitor = app.add_subcommand("monitor", "Replay a finished mission's trace in the browser (the URL is printed)");
  eamos::cli::MonitorCommandOptions monitor_opts;
  monitor->add_option("trace", monitor_opts.trace, "The trace (JSON Lines) `eamos run --trace` wrote")
      ->required()->check(eamos::cli::existing_file("a trace"));
  monitor->add_option("--port", monitor_opts.port, "Port to serve at (0: any free one)")
      ->default_val(8080)->check(eamos::cli::whole_number(0, 65535));
  monitor->add_option("--host", monitor_opts.host, "Numeric IP address to serve at (0.0.0.0: every interface; default 127.0.0.1, this machine only)")
      ->default_val("127.0.0.1");
  auto* monitor_mission = monitor->add_option("--mission", monitor_opts.mission,
                      "The mission, for a trace that does not carry it (an older trace): adds the graphs and the text")
      ->check(eamos::cli::existing_file("a mission file"));
  monitor->add_option("--fleet", monitor_opts.fleet, "The fleet file, with --mission")
      ->check(eamos::cli::existing_file("a fleet file"))->needs(monitor_mission);

  auto* gen = app.add_subcommand("gen-stress", "Generate a large valid mission for scaling tests");
  long long nodes = 5000;
  int work_per_step = 4;
  int drones = 20;
  unsigned seed = 1;
  std::string gen_out;
  std::string shape = "squads";
  gen->add_option("--shape", shape,
                  "squads: squads of ten, each its own barriers; show: every drone in every PAR; cross: squads that "
                  "wait on, branch on and fly to other squads' drones")
      ->check(eamos::cli::one_of({"squads", "show", "cross"}));
  gen->add_option("--work", work_per_step, "Work items per drone between two barriers")->check(eamos::cli::whole_number(1, 1000));
  gen->add_option("--nodes", nodes, "Approximate number of MEG nodes")->check(eamos::cli::whole_number(10, 50'000'000));
  gen->add_option("--drones", drones, "Number of drones")->check(eamos::cli::whole_number(1, 100000));
  gen->add_option("--seed", seed, "Seed of the generator (same seed, same mission)");
  gen->add_option("-o,--output", gen_out, "Output file (default: standard output)");

  auto* simv = app.add_subcommand("sim-vehicle", "Run a PX4-like MAVLink vehicle on the built-in simulator (for the mavlink adapter)");
  eamos::cli::SimVehicleCommandOptions simv_opts;
  auto* udp = simv->add_option("--udp", simv_opts.udp_port, "Send to 127.0.0.1:PORT, like PX4 SITL (whose instance i sends to 14540 + i)")
      ->check(eamos::cli::whole_number(1, 65535));
  simv->add_option("--gcs", simv_opts.ground_station,
                   "Also stream to a ground station so QGroundControl shows the vehicle, e.g. udpout://127.0.0.1:14550");
  simv->add_option("--connection", simv_opts.connection, "Any link URL instead: udp://:PORT, udpout://HOST:PORT or tcp://HOST:PORT")
      ->excludes(udp);
  simv->add_option("--sysid", simv_opts.sysid, "MAVLink system id")->check(eamos::cli::whole_number(1, 255));
  simv->add_option("--autopilot", simv_opts.autopilot, "Whose modes and rules to play: px4 (OFFBOARD) or ardupilot (Copter, GUIDED)")
      ->check(eamos::cli::one_of({"px4", "ardupilot"}));
  simv->add_option("--east", simv_opts.east, "Stand this many metres east of 47.397742 N, 8.545594 E (PX4 SITL's home); "
                   "give each vehicle its fleet home's x")->check(eamos::cli::number_between(-100000.0, 100000.0));
  simv->add_option("--north", simv_opts.north, "Stand this many metres north of it; the fleet home's y")
      ->check(eamos::cli::number_between(-100000.0, 100000.0));
  simv->add_option("--battery", simv_opts.battery, "Charge at start, %; 0 makes it refuse to arm")->check(eamos::cli::number_between(0.0, 100.0));
  simv->add_option("--speed", simv_opts.speed, "Mission time runs X times as fast as the wall clock; the adapter's run must use the same")
      ->check(eamos::cli::positive());
  simv->add_option("--duration", simv_opts.duration, "Stop after this many mission seconds (default: until interrupted)")
      ->check(eamos::cli::non_negative());

  auto* lsp = app.add_subcommand("lsp", "Serve the Language Server Protocol on standard input and output, for editors "
                                       "(docs/editors.md): diagnostics as you type, hover, go-to-definition, completion, outline");
  eamos::lsp::ServerOptions lsp_opts;
  lsp->add_option("--fleet", lsp_opts.fleet,
                  "Fleet file (YAML) to check every mission against, as `eamos check --fleet`; the client's "
                  "initializationOptions {\"fleet\": PATH} replace it");
  bool lsp_stdio = true;
  lsp->add_flag("--stdio", lsp_stdio, "Talk over standard input and output (the only transport; editors pass it)");

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
  style.color_stderr = eamos::cli::use_color(color, STDERR_FILENO);
  style.diagnostics = diagnostics_format;

  // Every file a command writes is checked before it compiles or flies anything: a run must
  // not end in "cannot write" after the flight.
  auto out = [](CLI::App* sub, const char* name, bool folder = false) {
    return eamos::cli::OutputPath{sub->get_option_no_throw(name), folder};
  };
  std::vector<std::pair<CLI::App*, std::vector<eamos::cli::OutputPath>>> outputs = {
      {compile, {out(compile, "--output", true)}},
      {graph, {out(graph, "--output")}},
      {stats, {out(stats, "--output")}},
      {gen, {out(gen, "--output")}},
      {run, {out(run, "--trace"), out(run, "--summary"), out(run, "--plot"), out(run, "--deploy-dir", true)}},
      {verify, {out(verify, "--plot"), out(verify, "--trace")}},
      {launch, {out(launch, "--trace"), out(launch, "--summary"), out(launch, "--plot")}},
      {dexcmd, {out(dexcmd, "--trace")}},
  };
  std::vector<std::string> inputs = {o.mission, o.fleet, monitor_opts.trace, monitor_opts.mission};
  for (const auto& [sub, paths] : outputs) {
    if (!*sub) continue;
    if (std::string bad = eamos::cli::check_outputs(*sub, args, paths, inputs); !bad.empty()) {
      std::cerr << bad;
      return 1;
    }
  }

  // A flight's live log goes out line by line also into a pipe (`| tee log`): what a person
  // watches is now, not a buffer later, and a killed process loses at most half a line.
  if (*run || *launch || *dexcmd || *simv || *monitor) std::setvbuf(stdout, nullptr, _IOLBF, BUFSIZ);

  try {
    if (*check) return eamos::cli::cmd_check(o, list_caps);
    if (*compile) return eamos::cli::cmd_compile(o, out_dir, security, packaged ? &package : nullptr);
    if (*graph) return eamos::cli::cmd_graph(o, kind, drone, format, graph_out);
    if (*stats) return eamos::cli::cmd_stats(o, stats_out);
    if (*run && distributed) {
      launch_opts.speed = run_opts.speed > 0 ? run_opts.speed : 1.0;
      launch_opts.time_limit_s = run_opts.time_limit;
      return eamos::cli::cmd_run_distributed(o, run_opts, launch_opts, security);
    }
    if (*run) return eamos::cli::cmd_run(o, run_opts);
    if (*verify) return eamos::cli::cmd_verify(o, verify_opts);
    if (*launch) return eamos::cli::cmd_launch(launch_opts, launch_report);
    if (*dexcmd) return eamos::cli::cmd_dex(dex_opts);
    if (*simv) return eamos::cli::cmd_sim_vehicle(simv_opts);
    if (*monitor) return eamos::cli::cmd_monitor(monitor_opts);
    if (*gen) return eamos::cli::cmd_gen_stress(shape, nodes, drones, work_per_step, seed, gen_out);
    if (*lsp) return eamos::lsp::serve_stdio(lsp_opts);
  } catch (const std::exception& e) {
    std::cerr << eamos::cli::error_prefix() << e.what() << "\n";
    return 1;
  }
  return 1;
}
