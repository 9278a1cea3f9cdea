// eamos: the command-line front of the Mission Compiler (and, later, of the DEX).
#include <CLI/CLI.hpp>

#include <iostream>

#include "cli/commands.h"
#include "version.h"

namespace {

void add_common(CLI::App* cmd, eamos::cli::CommonOptions& o) {
  cmd->add_option("mission", o.mission, "Mission file (.eamos)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--fleet", o.fleet, "Fleet file (YAML): drone types and per-drone settings")
      ->check(CLI::ExistingFile);
  cmd->add_option("--max-errors", o.max_errors, "Stop listing errors after N (0 = all)")
      ->default_val(200);
  cmd->add_flag("--werror", o.werror, "Treat warnings as errors");
  cmd->add_flag("-q,--quiet", o.quiet, "Do not print warnings");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"eamos — write a multidrone mission as a short program; every drone runs its part.",
               "eamos"};
  app.set_version_flag("--version", std::string("eamos ") + EAMOS_VERSION);
  app.require_subcommand(1);

  eamos::cli::CommonOptions o;

  auto* check = app.add_subcommand("check", "Check a mission and print every error and warning");
  add_common(check, o);
  bool list_caps = false;
  check->add_flag("--list-capabilities", list_caps, "Also list each drone's actions and properties");

  auto* compile = app.add_subcommand("compile", "Compile a mission into per-drone mission files and deployment folders");
  add_common(compile, o);
  std::string out_dir;
  compile->add_option("-o,--output", out_dir, "Output folder")->required();

  auto* graph = app.add_subcommand("graph", "Write the AMT, MEG or a drone's MDG as DOT, JSON or SVG");
  add_common(graph, o);
  std::string kind = "meg", drone, format = "dot", graph_out;
  graph->add_option("--kind", kind, "amt | meg | mdg")->check(CLI::IsMember({"amt", "meg", "mdg"}));
  graph->add_option("--drone", drone, "Drone whose MDG to write (with --kind mdg)");
  graph->add_option("--format", format, "dot | json | svg")->check(CLI::IsMember({"dot", "json", "svg"}));
  graph->add_option("-o,--output", graph_out, "Output file (default: standard output)");

  auto* stats = app.add_subcommand("stats", "Nodes and arcs per graph and per drone, as JSON");
  add_common(stats, o);
  std::string stats_out;
  stats->add_option("-o,--output", stats_out, "Output file (default: standard output)");

  auto* run = app.add_subcommand("run", "Compile and fly a mission in the built-in simulator; exit 0 only when it completed");
  add_common(run, o);
  eamos::cli::RunCommandOptions run_opts;
  run->add_option("--trace", run_opts.trace, "Write the trace as JSON Lines to this file");
  run->add_option("--summary", run_opts.summary, "Write the summary JSON to this file");
  run->add_option("--plot", run_opts.plot, "Draw the run (tracks and action timeline) as SVG to this file");
  auto* realtime = run->add_flag("--realtime", run_opts.realtime, "Run in real time instead of virtual time");
  run->add_option("--speed", run_opts.speed, "Real time scaled by X (2 = twice as fast)")
      ->check(CLI::PositiveNumber)->excludes(realtime);
  run->add_option("--time-limit", run_opts.time_limit, "Fail a mission still running after this many mission seconds")
      ->check(CLI::PositiveNumber);

  auto* gen = app.add_subcommand("gen-stress", "Generate a large valid mission for scaling tests");
  long long nodes = 5000;
  int drones = 20;
  unsigned seed = 1;
  std::string gen_out;
  gen->add_option("--nodes", nodes, "Approximate number of MEG nodes")->check(CLI::Range(10LL, 50'000'000LL));
  gen->add_option("--drones", drones, "Number of drones")->check(CLI::Range(1, 100000));
  gen->add_option("--seed", seed, "Seed of the generator (same seed, same mission)");
  gen->add_option("-o,--output", gen_out, "Output file (default: standard output)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? 0 : 1;
  }

  try {
    if (*check) return eamos::cli::cmd_check(o, list_caps);
    if (*compile) return eamos::cli::cmd_compile(o, out_dir);
    if (*graph) return eamos::cli::cmd_graph(o, kind, drone, format, graph_out);
    if (*stats) return eamos::cli::cmd_stats(o, stats_out);
    if (*run) return eamos::cli::cmd_run(o, run_opts);
    if (*gen) return eamos::cli::cmd_gen_stress(nodes, drones, seed, gen_out);
  } catch (const std::exception& e) {
    std::cerr << "eamos: error: " << e.what() << "\n";
    return 1;
  }
  return 1;
}
