#include "cli/commands.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "cli/arguments.h"
#include "diag/report.h"
#include "version.h"

#include "deploy/mission_file.h"
#include "deploy/synthesize.h"
#include "graph/export.h"
#include "graph/pipeline.h"
#include "security/mission_keys.h"  // remove_mission_keys only: no OpenSSL in `eamos`
#include "stress/generator.h"

namespace eamos::cli {

bool compile_and_report(const CommonOptions& o, graph::Compilation& c, graph::Keep keep) {
  Diagnostics diags;
  diags.max_errors = o.max_errors;
  bool ok = graph::compile_file(o.mission, o.fleet, diags, c, keep);
  // Re-list what the run found: -q drops warnings (and their notes), --werror turns them
  // into errors.
  Diagnostics shown;
  shown.max_errors = 0;
  bool skipping = false;
  for (Diagnostic d : diags.items()) {
    if (d.attached && skipping) continue;
    skipping = d.severity == Severity::warning && o.quiet;
    if (skipping) continue;
    if (d.severity == Severity::warning && o.werror) {
      d.severity = Severity::error;
      d.message += " [-Werror]";
    }
    shown.add(std::move(d));
  }
  print_diagnostics(shown, o.document_on_stdout);
  const OutputStyle& style = output_style();
  if (style.diagnostics != "text") {
    // The document says it all; a tool reads the exit status.
  } else if (diags.saturated()) {
    std::cerr << error_prefix() << "stopped listing after " << count_of(diags.max_errors, "error")
              << "; raise the limit with --max-errors N (0 for no limit)\n";
  }
  if (diags.has_errors()) {
    if (style.diagnostics == "text")
      std::cerr << count_of(diags.error_count(), "error") << ", " << count_of(diags.warning_count(), "warning") << "\n";
    return false;
  }
  if (o.werror && diags.warning_count() > 0) {
    if (style.diagnostics == "text")
      std::cerr << count_of(diags.warning_count(), "warning") << " treated as errors\n";
    return false;
  }
  return ok;
}

void print_diagnostics(const Diagnostics& diags, bool on_stdout) {
  const OutputStyle& style = output_style();
  std::ostream& out = on_stdout ? std::cout : std::cerr;
  if (style.diagnostics == "json") {
    out << diagnostics_json(diags);
  } else if (style.diagnostics == "sarif") {
    std::error_code ec;
    out << diagnostics_sarif(diags, "eamos", EAMOS_VERSION, std::filesystem::current_path(ec).string());
  } else {
    std::cerr << diags.format({.color = style.color_stderr});
  }
}

bool load_compiled_missions(const graph::Compilation& c, std::vector<dex::Mission>& missions) {
  std::vector<std::string> errors;
  if (deploy::compiled_missions(c, missions, errors)) return true;
  for (const std::string& e : errors) std::cerr << e << "\n";
  return false;
}

bool write_output(const std::string& path, const std::string& text) {
  if (path.empty() || path == "-") {
    std::cout << text;
    return static_cast<bool>(std::cout);
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) {
    std::cerr << error_prefix() << "cannot write '" << path << "'; check the path and permissions\n";
    return false;
  }
  return true;
}

void report_trace_write_errors(dex::JsonlTrace& trace, const std::string& path) {
  trace.on_write_error([path](const std::string& why) {
    std::cerr << "eamos: error: cannot write the trace '" << path << "' (" << why
              << "); it stops here, and the exit status will be 1\n"
              << std::flush;
  });
}

int cmd_check(const CommonOptions& o, bool list_capabilities) {
  graph::Compilation c;
  CommonOptions with_document = o;
  with_document.document_on_stdout = true;  // check's only output: `> report.sarif` takes it
  if (!compile_and_report(with_document, c)) return 1;
  // With a JSON or SARIF document on standard output, the summary goes to standard error.
  (output_style().diagnostics == "text" ? std::cout : std::cerr)
      << o.mission << ": ok — " << count_of(c.drone_count(), "drone") << ", " << count_of(c.amt.nodes.size(), "AMT node")
      << ", " << count_of(c.meg.nodes.size(), "MEG node") << "\n";
  if (list_capabilities) {
    for (int d = 0; d < c.drone_count(); ++d) {
      const auto& t = c.checked.drone_types[d];
      std::cout << c.drone_name(d) << " (" << t.name << ", adapter " << t.adapter << ")\n  actions:";
      for (const auto& a : t.actions) std::cout << " " << a.name << "(" << a.params << ")";
      std::cout << "\n  properties:";
      for (const auto& p : t.properties) std::cout << " " << p.name << "()";
      std::cout << "\n";
    }
  }
  return 0;
}

void warn_insecure(const char* command) {
  std::cerr << "eamos " << command << ": WARNING: --insecure: DDS Security is OFF. Anyone who can reach this "
               "network can read the mission and command, stop or crash every drone in it. Use it only for "
               "experiments, never with aircraft that can hurt anyone.\n";
}

std::vector<std::string> drone_names(const graph::Compilation& c) {
  std::vector<std::string> drones;
  for (int d = 0; d < c.drone_count(); ++d) drones.push_back(c.drone_name(d));
  return drones;
}

/// The deployment files and, with --package, each drone's package: everything that needs the
/// compiled graphs.
bool write_compiled_files(const graph::Compilation& c, const std::string& out_dir, const std::string& hash,
                          const SecurityOptions& security, const deploy::PackageOptions* package) {
  Diagnostics diags;
  if (!deploy::write_deployment(c, out_dir, hash, diags)) {
    std::cerr << diags.format();
    return false;
  }
  // Before the packages: they write the ground folder this would remove.
  if (security.insecure) security::remove_mission_keys(out_dir, drone_names(c));
  if (!package) return true;
  deploy::PackageOptions p = *package;
  p.insecure = security.insecure;
  p.ground_folder = security::kGroundFolder;
  if (deploy::write_packages(c, out_dir, p, diags)) return true;
  std::cerr << diags.format();
  return false;
}

/// What a compile prints once everything is written.
std::string compiled_message(const std::string& mission, const std::string& out_dir, std::size_t drones,
                             std::size_t meg_nodes, const deploy::PackageOptions* package) {
  std::ostringstream done;
  done << "compiled " << mission << " → " << out_dir << "/ (" << count_of(drones, "drone") << ", "
       << count_of(meg_nodes, "MEG node") << ")\n";
  if (package)
    done << "packaged each drone's DEX as a systemd service: " << out_dir << "/<drone>/DEPLOY.txt says what to "
         << "copy where" << (package->interface.empty() ? "; set EAMOS_DDS_INTERFACE in each dex.env" : "")
         << " (docs/deploy.md)\n";
  return done.str();
}

int cmd_compile(const CommonOptions& o, const std::string& out_dir, const SecurityOptions& security,
                const deploy::PackageOptions* package, CompileFinisher finish) {
  if (security.insecure) warn_insecure("compile");
  // An option that cannot be packaged is refused before anything is written.
  if (package) {
    if (std::string error = deploy::package_options_error(*package); !error.empty()) {
      std::cerr << error_prefix() << "" << error << "\n";
      return 1;
    }
  }
  auto c = std::make_unique<graph::Compilation>();
  if (!compile_and_report(o, *c, graph::Keep::deployment_graphs)) return 1;
  CompileEnding end{out_dir, deploy::mission_hash(*c), drone_names(*c), security, ""};
  if (!write_compiled_files(*c, out_dir, end.hash, security, package)) return 1;
  end.done = compiled_message(o.mission, out_dir, end.drones.size(), c->meg.nodes.size(), package);
  if (security.insecure) {
    std::cout << end.done;
    return 0;
  }
  // The credentials need only the hash and the drones' names. A finisher that replaces this
  // process takes the graphs' memory with it (freeing them would cost a millisecond of the
  // 5,000-statement compile); one in this process gets them freed first, for the credentials
  // to reuse, so the compile's peak memory is the larger of the two steps, not their sum.
  if (!finish.replaces_process) c.reset();
  return finish.run(end);
}

bool render_svg(const std::string& dot, std::string& svg, std::string& error) {
  char tmpl[] = "/tmp/eamos-graph-XXXXXX";
  int fd = mkstemp(tmpl);
  if (fd < 0) {
    error = "cannot create a temporary file";
    return false;
  }
  FILE* f = fdopen(fd, "w");
  std::fwrite(dot.data(), 1, dot.size(), f);
  std::fclose(f);
  std::string cmd = std::string("dot -Tsvg '") + tmpl + "' 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) {
    std::remove(tmpl);
    error = "cannot run Graphviz 'dot'";
    return false;
  }
  char buf[65536];
  std::size_t n;
  svg.clear();
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) svg.append(buf, n);
  int status = pclose(p);
  std::remove(tmpl);
  if (status != 0) {
    error = status == 127 * 256 || svg.find("not found") != std::string::npos
                ? "Graphviz 'dot' not found; install it with `apt-get install graphviz` (or run `make deps`)"
                : "Graphviz 'dot' failed: " + svg.substr(0, 500);
    return false;
  }
  return true;
}

int cmd_graph(const CommonOptions& o, const std::string& kind, const std::string& drone,
              const std::string& format, const std::string& output) {
  graph::Compilation c;
  if (!compile_and_report(o, c)) return 1;
  int d = -1;
  if (kind == "mdg") {
    if (drone.empty()) {
      std::cerr << error_prefix() << "--kind mdg needs --drone NAME; drones:";
      for (int i = 0; i < c.drone_count(); ++i) std::cerr << " " << c.drone_name(i);
      std::cerr << "\n";
      return 1;
    }
    d = c.find_drone(drone);
    if (d < 0) {
      std::cerr << error_prefix() << "no drone '" << drone << "' in " << o.mission << "; drones:";
      for (int i = 0; i < c.drone_count(); ++i) std::cerr << " " << c.drone_name(i);
      std::cerr << "\n";
      return 1;
    }
  } else if (!drone.empty()) {
    std::cerr << error_prefix() << "--drone only applies to --kind mdg\n";
    return 1;
  }
  if (format == "json") {
    nlohmann::json j = kind == "amt" ? graph::amt_json(c) : kind == "meg" ? graph::meg_json(c) : graph::mdg_json(c, d);
    return write_output(output, j.dump(2) + "\n") ? 0 : 1;
  }
  std::string dot = kind == "amt" ? graph::amt_dot(c) : kind == "meg" ? graph::meg_dot(c) : graph::mdg_dot(c, d);
  if (format == "dot") return write_output(output, dot) ? 0 : 1;
  std::string svg, error;
  if (!render_svg(dot, svg, error)) {
    std::cerr << error_prefix() << "" << error << "\n";
    return 1;
  }
  return write_output(output, svg) ? 0 : 1;
}

int cmd_stats(const CommonOptions& o, const std::string& output) {
  graph::Compilation c;
  if (!compile_and_report(o, c)) return 1;
  return write_output(output, graph::stats_json(c).dump(2) + "\n") ? 0 : 1;
}

int cmd_gen_stress(const std::string& shape, long long nodes, int drones, int work_per_step, unsigned seed,
                   const std::string& output) {
  stress::StressOptions opt;
  stress::shape_from_name(shape, opt.shape);  // the option accepts only the shapes' names
  opt.work_per_step = work_per_step;
  opt.target_nodes = nodes;
  opt.drones = drones;
  opt.seed = seed;
  return write_output(output, stress::generate_mission(opt)) ? 0 : 1;
}

}  // namespace eamos::cli
