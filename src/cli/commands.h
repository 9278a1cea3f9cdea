#pragma once
// The `eamos` subcommands. Each returns the process exit status: 0 success, 1 when the
// input had errors (all of them printed) or a file could not be read or written.
#include <sys/stat.h>
#include <unistd.h>

#include <condition_variable>
#include <mutex>
#include <string>

#include <nlohmann/json.hpp>

#include "deploy/drone_package.h"
#include "dex/runner.h"
#include "dex/trace_writers.h"
#include "graph/pipeline.h"
#include "launch/dex_process.h"
#include "launch/ground.h"

namespace eamos::monitor {
class MonitorServer;
}

namespace eamos::cli {

struct CommonOptions {
  std::string mission;        ///< the .eamos file
  std::string fleet;          ///< optional fleet YAML
  std::size_t max_errors = 200;
  bool werror = false;        ///< treat warnings as errors
  bool quiet = false;         ///< no warnings
  bool document_on_stdout = false;  ///< --diagnostics-format json|sarif: the document to stdout (check)
};

/// How a compiled mission's DDS Security credentials are made (docs/security.md).
struct SecurityOptions {
  std::string keys_dir;   ///< the CAs to sign with (made there when absent); "" = fresh ones
  bool insecure = false;  ///< no credentials at all: anyone on the network can command the drones
  int valid_days = 30;    ///< how long the credentials are valid
};

int cmd_check(const CommonOptions& o, bool list_capabilities);
/// What a compile has left to do once its mission files are written.
struct CompileEnding {
  std::string out_dir;
  std::string hash;                 ///< the mission hash
  std::vector<std::string> drones;  ///< by index
  SecurityOptions security;
  std::string done;                 ///< the lines to print once everything is written
};
/// Makes the credentials of `end` and prints `end.done`; the exit status. `eamos` replaces
/// itself with eamos-credentials for it (main.cpp): libcrypto is then never mapped beside the
/// compile's data. eamos-fly makes them in-process (`finish_in_process`).
struct CompileFinisher {
  int (*run)(const CompileEnding& end);
  bool replaces_process;  ///< exec: the compile's memory goes with the process image
};
int finish_in_process(const CompileEnding& end);
/// With `package`: also each drone's service files (deploy/drone_package.h, docs/deploy.md).
int cmd_compile(const CommonOptions& o, const std::string& out_dir, const SecurityOptions& security,
                const deploy::PackageOptions* package, CompileFinisher finish);
std::vector<std::string> drone_names(const graph::Compilation& c);
/// Writes (or, insecure, removes) the credentials of the deployment in `dir`; false with
/// the error printed.
bool write_security(const graph::Compilation& c, const std::string& dir, const std::string& hash,
                    const SecurityOptions& security);
/// The warning every insecure command prints first.
void warn_insecure(const char* command);
int cmd_graph(const CommonOptions& o, const std::string& kind, const std::string& drone,
              const std::string& format, const std::string& output);
int cmd_stats(const CommonOptions& o, const std::string& output);
struct RunCommandOptions {
  std::string trace;      ///< JSON Lines trace file; "" = none
  std::string summary;    ///< summary JSON file; "" = none
  std::string plot;       ///< SVG picture of the run (tracks and action timeline); "" = none
  bool realtime = false;
  double speed = 0.0;     ///< > 0: real time scaled by this factor
  double time_limit = 3600.0;
  bool log = true;        ///< print the live log
  std::string monitor;    ///< "[HOST:]PORT" to serve the run live in a browser; "" = none
  double telemetry_hz = 5.0;  ///< telemetry events per drone per mission second in the trace; 0 = none
};
int cmd_run(const CommonOptions& o, const RunCommandOptions& r);
/// Whether `eamos run` (in one process) writes its log in blocks rather than line by line:
/// on virtual time into a regular file, where nobody acts on a line the moment it is
/// written and a write per line cost a tenth of a 1,000-drone run. A terminal, a pipe and
/// a real-time run get each line as it happens. Inline: main() of the small `eamos` asks
/// it too, and must not link run.cpp (CMakeLists.txt, `--as-needed`).
inline bool run_log_in_blocks(const RunCommandOptions& r) {
  struct stat st {};
  return !r.realtime && r.speed <= 0 && fstat(STDOUT_FILENO, &st) == 0 && S_ISREG(st.st_mode);
}
/// Writes the summary and plot of a finished run as `eamos run` does; false when a file
/// could not be written.
bool report_run(const RunCommandOptions& r, const dex::RunResult& result, const std::vector<dex::TraceEvent>& events);
struct VerifyCommandOptions {
  int paths = 64;          ///< flights at most
  bool jitter = false;     ///< also fly each path with drones 10 % slower and faster
  double time_limit = 3600.0;
  bool json = false;       ///< the report as JSON on standard output
  std::string plot;        ///< SVG of the first path with the violations marked; "" = none
  std::string trace;       ///< JSON Lines trace of that path with its violation events; "" = none
};
/// `eamos verify`: exit 0 when no path breaks a rule, 1 otherwise (or on bad input).
int cmd_verify(const CommonOptions& o, const VerifyCommandOptions& v);
int cmd_dex(const launch::DexProcessOptions& options);
int cmd_launch(const launch::LaunchOptions& options, const RunCommandOptions& r);
int launch_with_monitor(const launch::LaunchOptions& options, const RunCommandOptions& r);
/// Writes the trace, summary and plot of a finished launch; the exit status.
int report_launch(const RunCommandOptions& r, const launch::LaunchResult& result, int status);
/// `eamos run --distributed`: compiles into options.dir (a temporary folder when ""), then launches.
int cmd_run_distributed(const CommonOptions& o, const RunCommandOptions& r, launch::LaunchOptions options,
                        const SecurityOptions& security);
struct SimVehicleCommandOptions {
  int udp_port = 14540;     ///< sends to udpout://127.0.0.1:PORT, like PX4 SITL instance 0
  std::string connection;   ///< any link URL instead of --udp; "" = use udp_port
  int sysid = 1;
  std::string autopilot = "px4";  ///< "px4" or "ardupilot": whose modes and rules it plays
  double battery = 100.0;   ///< % at start; 0 makes it refuse to arm
  double east = 0.0;        ///< m east of PX4 SITL's home where it stands (its fleet home's x)
  double north = 0.0;       ///< m north of it (its fleet home's y)
  double speed = 1.0;       ///< mission time runs this many times as fast as the wall clock
  double duration = 0.0;    ///< stop after this many mission seconds; 0 = until SIGINT/SIGTERM
  std::string ground_station;  ///< a second link URL for a GCS (QGroundControl); "" = none
};
int cmd_sim_vehicle(const SimVehicleCommandOptions& o);
int cmd_gen_stress(const std::string& shape, long long nodes, int drones, int work_per_step, unsigned seed,
                   const std::string& output);

struct MonitorCommandOptions {
  std::string trace;   ///< the JSONL trace to replay
  std::string host = "127.0.0.1";
  int port = 8080;     ///< 0: any free port
  std::string mission; ///< the mission, for a trace without a header; "" = the trace's own
  std::string fleet;
};
/// `eamos monitor`: serves the replay until SIGINT/SIGTERM; 1 when the trace has errors.
int cmd_monitor(const MonitorCommandOptions& m);
/// Waits, after a run with --monitor, until the user stops the process (Ctrl-C, SIGTERM).
struct MonitorHold {
  std::mutex mutex;
  std::condition_variable signalled;
  bool interrupted = false;
  void signal();
  bool was_interrupted();
  void wait_for_signal();
};
/// After the run: the page shows the finished mission until the user stops the process.
void hold_monitor(monitor::MonitorServer& server, MonitorHold& hold);
/// The live page's mission; runs Graphviz, so call it before any thread starts.
nlohmann::json live_view(const graph::Compilation& c, const std::string& mission, const std::string& fleet);
/// The live page's mission for `eamos launch DIR`.
nlohmann::json launch_view(const std::string& dir);
/// Parses `at` ("[HOST:]PORT") and starts `server` there; false with the error printed.
bool start_monitor(monitor::MonitorServer& server, const std::string& at, const nlohmann::json& view,
                   const std::string& option = "--monitor");

/// Prints diagnostics as --diagnostics-format and --color say: text on standard error, a
/// JSON or SARIF document on standard output when `on_stdout`, else on standard error.
void print_diagnostics(const Diagnostics& diags, bool on_stdout = false);
/// Compiles and prints every diagnostic; true when the graphs are usable.
bool compile_and_report(const CommonOptions& o, graph::Compilation& c,
                        graph::Keep keep = graph::Keep::all_graphs);
/// Every drone's mission built from the compiled MDGs in memory (deploy::compiled_missions):
/// the structure the validating reader makes of the files `eamos compile` writes, without
/// writing and parsing them (tests/deploy/mission_memory_test.cpp holds the two equal);
/// false (errors printed) when one cannot be built.
bool load_compiled_missions(const graph::Compilation& c, std::vector<dex::Mission>& missions);

/// Renders DOT to SVG with Graphviz `dot`; returns false with `error` set on failure.
bool render_svg(const std::string& dot, std::string& svg, std::string& error);
/// Writes text to a file, or to stdout when path is "" or "-".
bool write_output(const std::string& path, const std::string& text);
/// Makes a failed write of the trace at `path` an error on standard error the moment it
/// happens (a full disk): the trace stops there, what runs goes on.
void report_trace_write_errors(dex::JsonlTrace& trace, const std::string& path);

}  // namespace eamos::cli
