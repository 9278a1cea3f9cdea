#include "launch/ground.h"

#include <signal.h>

#include <algorithm>
#include <csignal>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <set>

#include <nlohmann/json.hpp>

#include "deploy/manifest.h"
#include "diag/file_read.h"
#include "diag/number.h"
#include "diag/source.h"
#include "launch/inbox.h"
#include "launch/process_watch.h"
#include "launch/spawn.h"
#include "launch/stop_signals.h"
#include "launch/wall_time.h"
#include "mid/home_check.h"

namespace eamos::launch {

using diag::number_text;

namespace {

using transport::LifecycleKind;
using transport::LifecycleSample;
using transport::Phase;
using transport::StatusSample;
using transport::TelemetrySample;
using transport::TraceSample;

struct DroneEntry {
  std::string name;
  std::string folder;  ///< absolute or relative to the working directory
  bool local = false;
  Child child;
  std::optional<std::uint64_t> ready_nonce;
  mid::HomeReport home;  ///< from its READY: declared home and where its vehicle stands
  double ready_speed = 0.0;  ///< from its READY: the speed its DEX runs at
  std::optional<StatusSample> final_status;
  std::vector<dex::Sample> track;
  std::optional<mid::DroneState> last_state;  ///< newest telemetry of this run
  std::optional<StatusSample> status;         ///< newest status of this run, from the process START named
  std::string refused;                        ///< why its DEX refused the start, if it did
  bool lost = false;                          ///< its DEX lost liveliness during the run
  double lost_at = 0.0;                       ///< wall time it was lost
  std::string log;
  double started_at = 0.0;  ///< wall time its DEX process was started
  bool started = false;     ///< its DEX process was started (by this launch, in its wave)
  bool heard = false;       ///< the ground has a sample of its DEX: their handshake is done
  int heard_drones = 0;     ///< other drones its DEX has heard from while waiting (its status)
};

bool read_manifest(const std::string& dir, std::string& hash, std::vector<DroneEntry>& drones, std::string& error) {
  deploy::DeploymentManifest m;
  if (!deploy::read_manifest(dir, m, error)) return false;
  hash = m.mission_hash;
  for (const deploy::DeployedDrone& d : m.drones) drones.push_back({d.name, dir + "/" + d.folder});
  return true;
}

std::string tail_of(const std::string& path, std::size_t lines) {
  std::ifstream in(path);
  std::vector<std::string> all;
  for (std::string line; std::getline(in, line);) all.push_back(line);
  std::string out;
  for (std::size_t i = all.size() > lines ? all.size() - lines : 0; i < all.size(); ++i) out += "    " + all[i] + "\n";
  return out;
}

/// Events the ground makes itself (telemetry samples, lifecycle messages): into the merged
/// trace, and to the live view (the plain log skips them, the terminal's status uses them).
class Collect : public dex::TraceSink {
 public:
  Collect(std::vector<dex::TraceEvent>& events, dex::TraceSink* live) : events_(events), live_(live) {}
  void record(const dex::TraceEvent& e) override {
    events_.push_back(e);
    if (live_) live_->record(e);
  }

 private:
  std::vector<dex::TraceEvent>& events_;
  dex::TraceSink* live_;
};

/// The trace header `eamos compile` wrote into the deployment (trace-header.json); from the
/// manifest alone (no mission or fleet text) when it is missing or not a header.
nlohmann::ordered_json load_header(const std::string& dir, const std::string& hash,
                                   const std::vector<DroneEntry>& drones, double telemetry_hz, std::ostream& err) {
  // It embeds the mission's and the fleet's text, each at most a source file's size.
  std::string text;
  diag::FileRead r = diag::read_bounded_file(dir + "/trace-header.json", 3 * kMaxSourceFileBytes, text);
  nlohmann::ordered_json h = nlohmann::ordered_json::parse(text, nullptr, false);
  const nlohmann::ordered_json none;
  bool usable = r.status == diag::FileRead::ok && h.is_object() && h.value("event", none) == "header" &&
                h.value("mission_hash", none) == hash;
  if (!usable) {
    err << "ground: " << dir << "/trace-header.json is missing or not this mission's; the trace's header will "
        << "not embed the mission and fleet text (compile the deployment again with this eamos)\n";
    h = nlohmann::ordered_json::object();
    h["t"] = 0;
    h["event"] = "header";
    h["schema"] = "eamos-trace";
    h["version"] = 1;
    h["mission"] = "";
    h["mission_hash"] = hash;
    h["source"] = "";
    h["fleet"] = "";
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (std::size_t d = 0; d < drones.size(); ++d)
      list.push_back({{"name", drones[d].name}, {"index", d}, {"type", ""}, {"home", {0.0, 0.0, 0.0}}});
    h["drones"] = list;
  }
  h["telemetry_hz"] = telemetry_hz;
  return h;
}

class Ground {
 public:
  Ground(const LaunchOptions& o, dex::TraceSink* live, LaunchResult& r, std::ostream& out, std::ostream& err)
      : o_(o), live_(live), r_(r), out_(out), err_(err), loop_(mid::ClockOptions{mid::ClockMode::real_time, 1.0}),
        collect_(r.events, live), telemetry_(&collect_, o.telemetry_hz) {}
  int run();

 private:
  bool prepare();
  bool choose_barrier_timeout();
  bool open_dds();
  bool fly();
  void report_outcome();
  void report_drones();
  int exit_status();
  void poll_children();
  void watch_barrier();
  std::string other_speeds() const;
  void watch_flight();
  double mission_now() const { return (unix_ns() - start_at_ns_) / 1e9 * o_.speed; }
  void record_lifecycle(const LifecycleSample& s);
  bool start_processes();
  /// Starts the next wave of DEX processes once every DEX started so far has been heard
  /// from (its discovery, and with DDS Security its handshakes, done); false on a failed spawn.
  bool start_next_wave();
  /// Starts `d`'s DEX; `later`: the drones this launch starts in later waves.
  bool start_one(DroneEntry& d, const std::string& exe, const std::vector<DroneEntry*>& later);
  /// Looks at what may have changed: a signal, the barrier, the flight's end. After every
  /// input that can change them, after a DEX process ended (poll_children first) and at
  /// each deadline; never on a timer of its own (the ground idles while the drones fly).
  void check();
  /// check() at `wall_s` seconds from now (a deadline: the barrier's, a lost drone's...).
  void check_after(double wall_s);
  void poll_on_timer();
  void send_start();
  void fail_barrier(const std::string& why);
  void on_lifecycle(const LifecycleSample& s);
  void on_run_lifecycle(const LifecycleSample& s);
  bool finish_agreed(int lead, std::string& why) const;
  void check_pending_finished();
  void reject(int sender, const std::string& what, const std::string& why);
  void on_refused(const LifecycleSample& s);
  void refuse_second_launch(const StatusSample& s);
  void on_status(const StatusSample& s);
  void on_trace(TraceSample s);
  /// Says on the console that message event `e` came later than --trigger-latency-warn.
  void warn_late(const dex::TraceEvent& e);
  /// ABORT when `e` (a message to a DEX started elsewhere) came later than --max-trigger-latency.
  void check_latency_bound(const dex::TraceEvent& e);
  /// Writes an ABORT of the running run (before anything is recorded), keeps the first one
  /// for the report and the trace, and says why on the console.
  void abort_run(const std::string& why);
  void on_telemetry(const TelemetrySample& s);
  bool ours(const std::string& hash);
  /// The run's mission time now, from the start instant the ground chose (0 before it).
  double mission_time() const {
    return start_at_ns_ > 0 ? std::max(0.0, (unix_ns() - start_at_ns_) / 1e9 * o_.speed) : 0.0;
  }
  bool all_done();
  void on_lost(const std::string& hash, int drone, std::uint64_t nonce);
  void interrupt();
  void stop_all(int signal);

  LaunchOptions o_;  // a copy: prepare() settles the barrier timeout
  dex::TraceSink* live_;
  LaunchResult& r_;
  std::ostream& out_;
  std::ostream& err_;
  mid::EventLoop loop_;
  Inbox inbox_;
  std::string hash_;
  std::vector<DroneEntry> drones_;
  enum class Stage { barrier, running, done } stage_ = Stage::barrier;
  double barrier_deadline_ = 0.0;  ///< the newest wave's: its start plus the barrier timeout
  double first_started_at_ = 0.0;  ///< wall time the first wave was started
  double wave_started_at_ = 0.0;   ///< wall time the newest wave was started
  double wall_guard_ = 0.0;
  std::optional<double> finish_at_;
  std::optional<LifecycleSample> abort_;
  std::optional<LifecycleSample> finished_;
  std::optional<LifecycleSample> pending_finished_;  ///< not agreed with (yet): see on_run_lifecycle
  std::set<std::string> rejected_;
  std::string error_;
  std::set<std::string> foreign_;
  std::vector<std::uint64_t> start_nonces_;
  std::int64_t start_at_ns_ = 0;  ///< Unix time of mission time 0 of the run
  /// This launch: its DEXes' READYs and its START carry it, so that a second launch of the
  /// same deployment does not take the first one's READYs (or the reverse).
  std::uint64_t launch_id_ = 0;
  int wave_size_ = 0;  ///< DEX processes started together: start_wave_for, or --start-wave
  bool polling_ = false;  ///< poll_on_timer runs: a child could not be watched by pidfd
  bool interrupted_ = false;
  Collect collect_;
  dex::TelemetryRecorder telemetry_;
  std::unique_ptr<ProcessWatch> watch_;  ///< DEX exits and signals wake the loop

  // Last, so it goes first: its listener threads post through inbox_ to loop_.
  std::unique_ptr<transport::DdsNode> node_;
};

volatile std::sig_atomic_t g_signal = 0;
void on_signal(int signal) {
  g_signal = signal;
  ProcessWatch::signal_arrived();
}

std::uint64_t random_id() {
  std::random_device rd;
  return ((static_cast<std::uint64_t>(rd()) << 32) | rd()) | 1;
}

int Ground::run() {
  launch_id_ = random_id();
  if (!prepare() || !open_dds()) return 1;
  if (!fly()) return 1;
  report_outcome();
  report_drones();
  return exit_status();
}

// The deployment: its manifest, the drones to start here, the trace's header.
bool Ground::prepare() {
  std::string error;
  if (!read_manifest(o_.dir, hash_, drones_, error)) {
    err_ << "eamos launch: error: " << error << "\n";
    return false;
  }
  std::set<std::string> names;
  for (auto& d : drones_) names.insert(d.name);
  for (const std::string& n : o_.local)
    if (!names.count(n)) {
      err_ << "eamos launch: error: --drones names '" << n << "', which is not a drone of this mission\n";
      return false;
    }
  if (!choose_barrier_timeout()) return false;
  r_.header = load_header(o_.dir, hash_, drones_, o_.telemetry_hz, err_);
  for (auto& d : drones_) r_.fleet.push_back(d.name);
  for (auto& d : drones_)
    d.local = !o_.remote_only &&
              (o_.local.empty() || std::find(o_.local.begin(), o_.local.end(), d.name) != o_.local.end());
  return true;
}

// Past Cyclone's handshake timeout a DEX of Debian's Cyclone DDS can crash (dds_node.h):
// with DDS Security a longer barrier is refused, and the default grows with the fleet.
bool Ground::choose_barrier_timeout() {
  const bool secure = !o_.insecure;
  if (o_.barrier_timeout_s <= 0) {
    o_.barrier_timeout_s = barrier_timeout_for(static_cast<int>(drones_.size()), secure);
    return true;
  }
  if (!secure || o_.barrier_timeout_s <= kMaxSecureBarrierS) return true;
  err_ << "eamos launch: error: --barrier-timeout " << number_text(o_.barrier_timeout_s)
       << " is longer than DDS Security allows: "
       << "Cyclone DDS gives up a handshake after " << transport::kHandshakeGiveUpS
       << " s, and Debian 12's build can crash then; use --barrier-timeout " << kMaxSecureBarrierS
       << " or less (a fleet whose handshakes need longer is too large for this host: docs/performance.md)\n";
  return false;
}

// Discovery: the ground's DDS participant, every sample handed to the loop's thread.
bool Ground::open_dds() {
  transport::DdsHandlers h;
  h.lifecycle = [this](LifecycleSample s) {
    inbox_.deliver([this, s] {
      on_lifecycle(s);
      check();
    });
  };
  h.status = [this](StatusSample s) {
    inbox_.deliver([this, s] {
      on_status(s);
      check();
    });
  };
  h.trace = [this](TraceSample s) { inbox_.deliver([this, s] { on_trace(s); }); };
  h.telemetry = [this](TelemetrySample s) { inbox_.deliver([this, s] { on_telemetry(s); }); };
  h.lost = [this](const std::string& hash, int drone, std::uint64_t nonce) {
    inbox_.deliver([this, hash, drone, nonce] {
      on_lost(hash, drone, nonce);
      check();
    });
  };
  // Logged on the ground's own thread: the listener that dropped the sample only posts.
  h.dropped = [this](const std::string& line) { inbox_.deliver([this, line] { err_ << "ground: " << line << "\n"; }); };
  h.limits.drones = static_cast<int>(drones_.size());
  transport::DdsOptions dds = o_.dds;
  dds.mission_hash = hash_;
  dds.self = transport::kGroundParticipant;
  if (!o_.insecure) dds.security_folder = o_.dir + "/ground-station/security";
  std::string error;
  node_ = transport::DdsNode::open(dds, std::move(h), error);
  if (!node_) {
    err_ << "eamos launch: error: " << error << "\n";
    return false;
  }
  // A sample that makes a handler throw is dropped; the ground keeps collecting the report.
  loop_.on_callback_error([this](const std::string& what) { err_ << "ground: dropped an input: " << what << "\n"; });
  inbox_.attach(loop_, [](const TelemetrySample&) {});
  return true;
}

// From the DEX processes' start to their end: the barrier, the run and its end (check).
bool Ground::fly() {
  // waitpid needs SIGCHLD at its default; Ctrl-C, a TERM or a hangup aborts the run (every
  // drone runs its failsafe) instead of killing the ground in the middle of it.
  std::signal(SIGCHLD, SIG_DFL);
  on_stop_signals(on_signal);
  first_started_at_ = wave_started_at_ = wall_s();
  barrier_deadline_ = first_started_at_ + o_.barrier_timeout_s;
  watch_ = std::make_unique<ProcessWatch>([this] {
    loop_.post([this] {
      poll_children();
      check();
    });
  });
  watch_->start();
  if (!start_processes()) {
    stop_all(SIGTERM);
    watch_.reset();
    node_.reset();
    return false;
  }
  check_after(o_.barrier_timeout_s);
  // From inside the run: a stop() before it would be forgotten.
  loop_.post([this] {
    poll_children();
    check();
  });
  loop_.run_until(1e9);
  watch_.reset();
  node_.reset();
  for (auto& d : drones_)
    if (d.local) reap(d.child, 5.0);
  return true;
}

// The report, in the shape `eamos run` gives: how and when the mission ended.
void Ground::report_outcome() {
  std::stable_sort(r_.events.begin(), r_.events.end(),
                   [](const dex::TraceEvent& a, const dex::TraceEvent& b) { return a.t < b.t; });
  dex::RunResult& run = r_.run;
  run.completed = finished_.has_value() && !abort_ && error_.empty();
  if (abort_) {
    run.failure = abort_->failure;
    run.error = abort_->reason;
    run.duration = abort_->t;  // the mission time of the abort, not of the last landing
  } else if (finished_) {
    run.duration = finished_->t;
  }
  if (!error_.empty()) run.error = error_;
  run.latency = dex::message_latency(r_.events, r_.fleet, o_.latency_warn_s);
  // The merged trace ends like an in-process one: how and when the mission ended.
  dex::TraceEvent end = dex::mission_end_event(run);
  if (live_) live_->record(end);
  r_.events.push_back(end);
}

void Ground::report_drones() {
  dex::RunResult& run = r_.run;
  for (auto& d : drones_) {
    // A drone without a final status (lost and not back, its DEX died) is reported as
    // unknown, with what was last seen of it.
    mid::DroneState seen = d.status ? d.status->state : mid::DroneState{};
    mid::DroneState state = d.final_status ? d.final_status->state : d.last_state.value_or(seen);
    // Before a start nothing moved: what the waiting DEXes published is where they are.
    bool final = d.final_status.has_value() || r_.run_id == 0;
    run.drones.push_back({d.name, state, d.track, final});
    if (d.final_status) run.activations += d.final_status->activations;
    if (!final)
      err_ << "ground: " << d.name << "'s final state is unknown: "
           << (!d.refused.empty() ? "its DEX refused this run"
               : d.lost            ? "no contact since it was lost"
                                   : "its DEX ended without reporting it")
           << "\n";
  }
}

// 0 when the mission completed and every DEX started here exited cleanly.
int Ground::exit_status() {
  int status = r_.run.completed ? 0 : 1;
  for (auto& d : drones_)
    if (d.local && d.child.exit_status && *d.child.exit_status != 0 && r_.run.completed) {
      err_ << "ground: the DEX of " << d.name << " exited with status " << *d.child.exit_status << "; its log:\n"
           << tail_of(d.log, 10);
      status = 1;
    }
  return status;
}

bool Ground::start_processes() {
  int local = static_cast<int>(std::count_if(drones_.begin(), drones_.end(), [](const DroneEntry& d) { return d.local; }));
  wave_size_ = o_.start_wave > 0 ? o_.start_wave : start_wave_for(local, !o_.insecure);
  if (wave_size_ < local)
    out_ << "ground: starting " << local << " DEX processes in waves of " << wave_size_
         << ", each once the DEXes before it have heard from each other\n";
  return start_next_wave();
}

bool Ground::start_next_wave() {
  int started = 0, waiting = 0;
  for (const auto& d : drones_) {
    started += d.started;
    waiting += d.local && !d.started;
  }
  if (waiting == 0) return true;
  // The last wave is still joining until the ground has heard from each DEX started so far
  // and each of them from all the others.
  for (const auto& d : drones_)
    if (d.started && (!d.heard || (d.heard_drones < started - 1 && !d.ready_nonce))) return true;
  if (started > 0) {
    char took[64];
    std::snprintf(took, sizeof took, "%.1f", wall_s() - first_started_at_);
    out_ << "ground: the " << started << " DEX processes started so far have heard from each other (" << took
         << " s after the first was started); starting " << std::min(waiting, wave_size_) << " more\n";
    // Each wave has the whole barrier timeout from its own start: a handshake begins only
    // when the later of its two DEXes starts, so no handshake stays pending longer than
    // that, however many waves the fleet needs (with DDS Security, kMaxSecureBarrierS).
    wave_started_at_ = wall_s();
    barrier_deadline_ = wave_started_at_ + o_.barrier_timeout_s;
    check_after(o_.barrier_timeout_s);
  }
  std::vector<DroneEntry*> wave, later;
  for (auto& d : drones_)
    if (d.local && !d.started) (static_cast<int>(wave.size()) < wave_size_ ? wave : later).push_back(&d);
  std::string exe = o_.exe.empty() ? self_exe() : o_.exe;
  for (DroneEntry* d : wave) {
    if (!start_one(*d, exe, later)) return false;
    if (!watch_->watch(d->child.pid) && !polling_) {
      polling_ = true;
      poll_on_timer();
    }
  }
  out_ << std::flush;
  return true;
}

bool Ground::start_one(DroneEntry& d, const std::string& exe, const std::vector<DroneEntry*>& later) {
  char number[64];
  std::vector<std::string> argv = {exe, "dex", d.folder, "--domain", std::to_string(o_.dds.domain)};
  if (!o_.dds.interface.empty()) argv.insert(argv.end(), {"--interface", o_.dds.interface});
  if (!o_.dds.config_file.empty()) argv.insert(argv.end(), {"--dds-config", o_.dds.config_file});
  std::snprintf(number, sizeof number, "%.17g", o_.speed);
  argv.insert(argv.end(), {"--speed", number});
  std::snprintf(number, sizeof number, "%.17g", o_.dds.lease_s);
  argv.insert(argv.end(), {"--liveliness-timeout", number});
  std::snprintf(number, sizeof number, "%.17g", o_.time_limit_s);
  argv.insert(argv.end(), {"--time-limit", number});
  // This wave and every later one may take the whole barrier timeout.
  const int waves_left = 1 + (static_cast<int>(later.size()) + wave_size_ - 1) / wave_size_;
  std::snprintf(number, sizeof number, "%.17g", waves_left * o_.barrier_timeout_s + 5.0);
  argv.insert(argv.end(), {"--start-timeout", number});
  if (!later.empty()) {
    // Not waited for within its ready timeout: each of them starts later and answers for
    // its own handshakes (DexProcessOptions::later_drones).
    std::string names;
    for (const DroneEntry* l : later) names += (names.empty() ? "" : ",") + l->name;
    argv.insert(argv.end(), {"--later-drones", names});
  }
  if (o_.insecure) argv.push_back("--insecure");
  if (o_.state_rate_hz > 0) {
    std::snprintf(number, sizeof number, "%.17g", o_.state_rate_hz);
    argv.insert(argv.end(), {"--state-rate", number});
  }
  if (o_.max_trigger_latency_s > 0) {
    std::snprintf(number, sizeof number, "%.17g", o_.max_trigger_latency_s);
    argv.insert(argv.end(), {"--max-trigger-latency", number});
  }
  argv.insert(argv.end(), {"--launch-id", std::to_string(launch_id_)});
  d.log = d.folder + "/dex.log";
  std::remove(d.log.c_str());
  std::string error;
  d.started_at = wall_s();
  d.child = spawn(argv, d.log, error);
  d.started = true;
  if (d.child.pid < 0) {
    err_ << "eamos launch: error: " << error << "\n";
    return false;
  }
  out_ << "ground: started the DEX of " << d.name << " (pid " << d.child.pid << ", log " << d.log << ")\n";
  return true;
}

void Ground::check() {
  if (g_signal != 0 && stage_ != Stage::done) {
    // A second time: stop the DEXes now (a DEX takes SIGTERM as "abandon the mission",
    // which it already does), leaving each drone in the failsafe it was commanded.
    if (interrupted_) stop_all(SIGKILL);
    interrupt();
  }
  if (stage_ == Stage::barrier) watch_barrier();
  else if (stage_ == Stage::running) watch_flight();
  if (stage_ == Stage::done) loop_.stop();
}

void Ground::check_after(double seconds) {
  // A hair late rather than early: the checks compare wall times with their deadlines.
  loop_.after(seconds + 0.01, [this] { check(); });
}

void Ground::poll_on_timer() {
  // Only where the kernel has no pidfds (before Linux 5.3): the children are looked at twice
  // a second instead.
  loop_.after(0.5, [this] {
    poll_children();
    check();
    if (stage_ != Stage::done) poll_on_timer();
  });
}

void Ground::poll_children() {
  for (auto& d : drones_) {
    if (!d.local || d.child.exit_status) continue;
    poll(d.child);
    if (!d.child.exit_status) continue;
    char usage[96];
    std::snprintf(usage, sizeof usage, " (%.2f CPU-s, peak RSS %.1f MB)", d.child.cpu_s, d.child.max_rss_kb / 1024.0);
    out_ << "ground: the DEX of " << d.name << " exited with status " << *d.child.exit_status << usage << "\n"
         << std::flush;
  }
}

// The start barrier: START once every drone is READY; a DEX that died first or a barrier
// past its deadline fails the launch before anything moved.
void Ground::watch_barrier() {
  if (!start_next_wave()) return fail_barrier("a DEX process could not be started");
  for (auto& d : drones_)
    if (d.local && d.child.exit_status && !d.ready_nonce)
      return fail_barrier("the DEX of " + d.name + " exited with status " + std::to_string(*d.child.exit_status) +
                          " before it was ready; its log (" + d.log + "):\n" + tail_of(d.log, 10));
  bool all = std::all_of(drones_.begin(), drones_.end(), [](const DroneEntry& d) { return d.ready_nonce.has_value(); });
  if (all) {
    if (std::string slow = other_speeds(); !slow.empty()) return fail_barrier(slow);
    std::vector<mid::HomeReport> homes;
    for (const auto& d : drones_) homes.push_back(d.home);
    if (std::string wrong = mid::compare_homes(homes); !wrong.empty())
      return fail_barrier("the vehicles do not stand where the fleet file puts them; nothing was armed:\n" + wrong);
    send_start();
  } else if (wall_s() > barrier_deadline_) {
    std::string missing;
    for (auto& d : drones_)
      if (!d.ready_nonce) missing += (missing.empty() ? "" : ", ") + d.name;
    char secs[160];
    std::snprintf(secs, sizeof secs, "%g s", o_.barrier_timeout_s);
    if (wave_started_at_ > first_started_at_) {
      auto is_started = [](const DroneEntry& d) { return d.started; };
      int started = static_cast<int>(std::count_if(drones_.begin(), drones_.end(), is_started));
      std::snprintf(secs + std::strlen(secs), sizeof secs - std::strlen(secs),
                    " of the wave started %.1f s after the first DEX (%d DEX processes started)",
                    wave_started_at_ - first_started_at_, started);
    }
    fail_barrier(std::string("start barrier timed out after ") + secs + "; not ready: " + missing);
  }
}

// A DEX started elsewhere at another --speed would count mission time at another rate than
// every other drone. Refused here, before any START: refused by that DEX at the START, its
// ABORT would have to reach every other DEX before their start instant, which a loaded host
// or a slow network does not promise.
std::string Ground::other_speeds() const {
  std::string which;
  for (const DroneEntry& d : drones_)
    if (d.ready_speed != o_.speed) which += (which.empty() ? "" : ", ") + d.name + " at " + number_text(d.ready_speed);
  if (which.empty()) return "";
  return "a DEX runs at another speed than the ground (--speed " + number_text(o_.speed) + "): " + which +
         "; nothing was armed: start it with --speed " + number_text(o_.speed);
}

// The flight: done once every drone has its final state (all_done), or when the DEXes
// overran the wall-clock guard.
void Ground::watch_flight() {
  if (wall_s() > wall_guard_) {
    error_ = "the DEX processes did not report an end in time";
    stop_all(SIGKILL);
    stage_ = Stage::done;
  } else if (all_done()) {
    if (!finish_at_) {
      finish_at_ = wall_s() + 0.3;  // the last trace samples may still be on the way
      check_after(0.3);
    }
    if (wall_s() > *finish_at_) stage_ = Stage::done;
  }
}

bool Ground::all_done() {
  // Every drone's final state, after its failsafe: a drone that was lost may come back (a
  // network cut that ended) and report it; one that does not within the bound is unknown.
  for (auto& d : drones_) {
    if (d.local && !d.child.exit_status) return false;
    bool gave_up = (d.lost && wall_s() > d.lost_at + o_.final_state_timeout_s) || !d.refused.empty();
    if (!d.local && !d.final_status && !gave_up) return false;
  }
  return true;
}

void Ground::on_lost(const std::string& hash, int drone, std::uint64_t nonce) {
  if (hash != hash_ || drone < 0 || drone >= static_cast<int>(drones_.size()) || stage_ != Stage::running) return;
  DroneEntry& d = drones_[drone];
  if (d.final_status || static_cast<int>(start_nonces_.size()) <= drone || start_nonces_[drone] != nonce) return;
  if (d.lost) return;
  d.lost = true;  // wait for its final status only so long (all_done)
  d.lost_at = wall_s();
  check_after(o_.final_state_timeout_s);
  err_ << "ground: " << d.name << " lost its liveliness\n";
}

void Ground::interrupt() {
  interrupted_ = true;
  std::string why = std::string("the ground was interrupted (") + stop_signal_name(g_signal) + ")";
  g_signal = 0;
  if (stage_ == Stage::barrier) return fail_barrier(why);
  abort_run(why);
}

void Ground::abort_run(const std::string& why) {
  LifecycleSample abort{hash_, transport::kGround, LifecycleKind::abort, r_.run_id};
  abort.reason = why;
  abort.t = mission_time();
  node_->write(abort);  // first: the drones' failsafe must not wait for a terminal
  if (!abort_) {
    abort_ = abort;
    LifecycleSample heard = abort;
    heard.t = mission_now();  // for the trace only: the report keeps what it always said
    record_lifecycle(heard);
  }
  err_ << "ground: " << why << "; aborting the run: every drone runs its failsafe\n";
}

void Ground::send_start() {
  LifecycleSample start;
  start.mission_hash = hash_;
  start.drone = transport::kGround;
  start.kind = LifecycleKind::start;
  start.run_id = random_id();
  start.launch_id = launch_id_;
  start.start_at_ns = unix_ns() + static_cast<std::int64_t>(o_.start_delay_s * 1e9);
  start.speed = o_.speed;
  for (auto& d : drones_) start.nonces.push_back(*d.ready_nonce);
  start_nonces_ = start.nonces;
  start_at_ns_ = start.start_at_ns;
  node_->write(start);
  r_.run_id = start.run_id;
  stage_ = Stage::running;
  wall_guard_ = wall_s() + o_.start_delay_s + o_.time_limit_s / o_.speed + 700.0 / o_.speed + 30.0;
  check_after(wall_guard_ - wall_s());
  char took[64];
  std::snprintf(took, sizeof took, "%.1f", wall_s() - first_started_at_);
  out_ << "ground: every drone is ready; starting run " << start.run_id << " (" << took
       << " s after the first DEX was started)\n" << std::flush;
}

void Ground::fail_barrier(const std::string& why) {
  error_ = why;
  err_ << "eamos launch: error: " << why << "\n";
  // DEXes started elsewhere wait for a start; tell them there will be none (run 0).
  LifecycleSample abort{hash_, transport::kGround, LifecycleKind::abort, 0};
  abort.reason = why;
  abort.launch_id = launch_id_;  // the DEXes of another launch keep waiting for theirs
  node_->write(abort);
  node_->flush(1.0);
  stop_all(SIGTERM);
  stage_ = Stage::done;
  loop_.stop();
}

void Ground::stop_all(int signal) {
  for (auto& d : drones_)
    if (d.local && d.child.pid > 0 && !d.child.exit_status) kill(d.child.pid, signal);
}

bool Ground::ours(const std::string& hash) {
  if (hash == hash_) return true;
  if (foreign_.insert(hash).second)
    err_ << "ground: ignoring messages of another mission (hash " << hash.substr(0, 12) << "…) on DDS domain "
         << o_.dds.domain << "\n";
  return false;
}

void Ground::on_lifecycle(const LifecycleSample& s) {
  if (!ours(s.mission_hash)) return;
  if (s.kind == LifecycleKind::ready) {
    if (stage_ != Stage::barrier || s.drone < 0 || s.drone >= static_cast<int>(drones_.size())) return;
    if (s.launch_id != 0 && s.launch_id != launch_id_) return;  // another launch's DEX
    DroneEntry& d = drones_[s.drone];
    if (!d.ready_nonce) {
      out_ << "ground: " << d.name << " ready";
      if (d.local) out_ << " (" << static_cast<long>((wall_s() - d.started_at) * 1000) << " ms after its process started)";
      out_ << "\n" << std::flush;
    }
    drones_[s.drone].ready_nonce = s.nonce;
    drones_[s.drone].home = {d.name, {s.home_x, s.home_y, 0.0}, s.fix, s.home_tolerance};
    drones_[s.drone].ready_speed = s.speed;
    return;
  }
  if (s.run_id != r_.run_id || stage_ != Stage::running) return;
  if (s.kind == LifecycleKind::refused) return on_refused(s);
  on_run_lifecycle(s);
}

void Ground::on_refused(const LifecycleSample& s) {
  if (s.launch_id != launch_id_ || s.drone < 0 || s.drone >= static_cast<int>(drones_.size())) return;
  DroneEntry& d = drones_[s.drone];
  if (!d.refused.empty() || start_nonces_[s.drone] != s.nonce) return;
  d.refused = s.reason.empty() ? "no reason given" : s.reason;
  // Nothing of this run may fly beside the run that DEX flies: every DEX of it lands.
  LifecycleSample abort{hash_, transport::kGround, LifecycleKind::abort, r_.run_id};
  abort.reason = "the DEX of " + d.name + " refused the start: " + d.refused;
  abort.t = mission_time();
  node_->write(abort);
  if (!abort_) abort_ = abort;
  error_ = abort.reason;
  err_ << "eamos launch: error: " << abort.reason << "\n";
}

void Ground::refuse_second_launch(const StatusSample& s) {
  // A status of this mission in a run while this launch waits at its barrier: a DEX of
  // another launch flies (or lands) this deployment now. Starting a second copy would put
  // two DEXes on one drone.
  if (s.run_id == 0 || (s.phase != Phase::running && s.phase != Phase::failsafe)) return;
  if (s.drone < 0 || s.drone >= static_cast<int>(drones_.size())) return;
  fail_barrier("this deployment is already running: the DEX of " + drones_[s.drone].name + " is " +
               (s.phase == Phase::running ? "flying" : "landing") + " run " + std::to_string(s.run_id) +
               "; a second launch of a running deployment is refused (stop the first one, or wait for it to end)");
}

void Ground::reject(int sender, const std::string& what, const std::string& why) {
  std::string name = sender >= 0 && sender < static_cast<int>(drones_.size()) ? drones_[sender].name : "the ground";
  if (rejected_.insert(std::to_string(sender) + " " + what + " " + why).second)
    err_ << "ground: ignored a " << what << " sample from " << name << ": " << why << "\n";
}

void Ground::on_run_lifecycle(const LifecycleSample& s) {
  if (s.kind == LifecycleKind::abort && !abort_) {
    if (s.failure && std::none_of(drones_.begin(), drones_.end(),
                                  [&](const DroneEntry& d) { return d.name == s.failure->drone; }))
      return reject(s.drone, "abort", "the failed drone it names is not in the mission");
    if (!(s.t >= 0.0)) return reject(s.drone, "abort", "its mission time is negative");
    abort_ = s;
    record_lifecycle(s);
  }
  // FINISHED only from the lead, and only when the statuses say what the lead saw; it may
  // come before the last statuses do, so it waits for them (check_pending_finished).
  if (s.kind == LifecycleKind::finished && !finished_) {
    if (s.drone == transport::kGround) return reject(s.drone, "finished", "only the lead drone ends a mission");
    pending_finished_ = s;
    check_pending_finished();
  }
}

bool Ground::finish_agreed(int lead, std::string& why) const {
  const std::optional<StatusSample>& ls = drones_[lead].status;
  if (!ls || !ls->end_reached) {
    why = "its sender has not reached the mission's end";
    return false;
  }
  std::uint64_t sent = 0, received = 0;
  for (const DroneEntry& d : drones_) {
    if (!d.status || d.status->busy) {
      why = d.name + " is still busy";
      return false;
    }
    sent += d.status->sent;
    received += d.status->received;
  }
  if (sent != received) {
    why = "triggers are still in flight";
    return false;
  }
  return true;
}

void Ground::check_pending_finished() {
  if (!pending_finished_ || finished_) return;
  std::string why;
  if (finish_agreed(pending_finished_->drone, why)) {
    finished_ = pending_finished_;
    pending_finished_.reset();
    record_lifecycle(*finished_);
  } else if (all_done()) {
    reject(pending_finished_->drone, "finished", why);
  }
}

void Ground::on_status(const StatusSample& s) {
  // Statuses of waiting DEXes (run 0) say nothing the barrier needs: READY does.
  if (stage_ == Stage::barrier && s.mission_hash == hash_) {
    if (s.run_id == 0 && s.phase == Phase::waiting && s.drone >= 0 && s.drone < static_cast<int>(drones_.size()))
      drones_[s.drone].heard_drones = std::max(drones_[s.drone].heard_drones, s.heard);
    return refuse_second_launch(s);
  }
  if (stage_ != Stage::running) return;
  if (!ours(s.mission_hash) || s.run_id != r_.run_id || s.drone < 0 || s.drone >= static_cast<int>(drones_.size()))
    return;
  // Bound to the process START named: a second process with that drone's credentials
  // (restarted, copied) does not speak for it.
  if (static_cast<int>(start_nonces_.size()) <= s.drone || start_nonces_[s.drone] != s.nonce)
    return reject(s.drone, "status", "it comes from another process than the one this run was started with");
  drones_[s.drone].status = s;
  if (s.phase == Phase::completed || s.phase == Phase::failed) drones_[s.drone].final_status = s;
  check_pending_finished();
}

void Ground::on_trace(TraceSample s) {
  if (!ours(s.mission_hash) || s.run_id != r_.run_id || s.drone < 0 || s.drone >= static_cast<int>(drones_.size()))
    return;
  s.event.drone = drones_[s.drone].name;
  if (dex::is_drone_message(s.event)) {
    if (dex::latency_of(s.event) > o_.latency_warn_s) warn_late(s.event);
    check_latency_bound(s.event);
  }
  if (live_) {
    live_->record(s.event);
    out_ << std::flush;  // a live log: whoever watches it (a person, a test) sees each event now
  }
  r_.events.push_back(std::move(s.event));
}

void Ground::warn_late(const dex::TraceEvent& e) {
  err_ << "ground: warning: " << dex::describe_late(dex::late_message(e, r_.fleet))
       << ", later than --trigger-latency-warn " << number_text(o_.latency_warn_s) << " s\n";
}

void Ground::check_latency_bound(const dex::TraceEvent& e) {
  // A DEX started here has the bound itself and abandons first; one started elsewhere may
  // have been started without it, so the ground holds it for that drone.
  double bound = o_.max_trigger_latency_s;
  if (bound <= 0 || dex::latency_of(e) <= bound || stage_ != Stage::running || abort_) return;
  if (e.to < 0 || e.to >= static_cast<int>(drones_.size()) || drones_[e.to].local) return;
  char limit[64];
  std::snprintf(limit, sizeof limit, ", later than --max-trigger-latency %g s", bound);
  abort_run(dex::describe_late(dex::late_message(e, r_.fleet)) + limit + " (held by the ground: " +
            drones_[e.to].name + "'s DEX was started elsewhere)");
}

void Ground::on_telemetry(const TelemetrySample& s) {
  const dex::Telemetry& t = s.telemetry;
  if (!ours(t.mission_hash) || t.from < 0 || t.from >= static_cast<int>(drones_.size())) return;
  // Run 0 is a waiting DEX's initial state: the drone's, before the start; during the run
  // it can only come from a DEX started again, which does not fly.
  if (s.run_id != (stage_ == Stage::barrier ? 0 : r_.run_id)) return;
  if (stage_ == Stage::barrier && !drones_[t.from].heard) {
    drones_[t.from].heard = true;  // its DEX's first sample: the next wave may start
    loop_.post([this] { check(); });
  }
  dex::record_sample(drones_[t.from].track, t.state);
  drones_[t.from].last_state = t.state;
  // The DEXes publish on every change (20 Hz while moving): the trace keeps telemetry_hz.
  const std::string& name = drones_[t.from].name;
  if (stage_ == Stage::running && telemetry_.due(name, t.state.t)) telemetry_.sample(name, t.state, t.state.t);
}

void Ground::record_lifecycle(const LifecycleSample& s) {
  // The ground hears of it at its own estimate of mission time, never before it was sent.
  dex::TraceEvent e;
  e.event = "message";
  e.kind = s.kind == LifecycleKind::abort ? "abort" : "finished";
  e.from = s.drone;
  e.to = -1;
  e.sent = s.t;
  e.t = std::max(s.t, mission_now());
  e.reason = s.reason;
  collect_.record(e);
}

}  // namespace

int start_wave_for(int drones, bool secure) {
  // Each DEX that joins authenticates with every participant already there (and they with
  // it): a wave of w joining n costs w * n + w * (w - 1) / 2 handshakes at once. Twenty
  // secure DEXes at once were ready on this 2-core host, thirty were not.
  int wave = !secure ? kInsecureStartWave : drones > kLargeSecureFleet ? kLargeSecureStartWave : kSecureStartWave;
  return drones <= wave ? std::max(1, drones) : wave;
}

double barrier_timeout_for(int drones, bool secure) {
  double s = 30.0 + 0.5 * std::max(0, drones - 20);
  return secure ? std::min(s, kMaxSecureBarrierS) : s;
}

int launch(const LaunchOptions& options, dex::TraceSink* live, LaunchResult& result, std::ostream& out,
           std::ostream& err) {
  Ground g(options, live, result, out, err);
  return g.run();
}

}  // namespace eamos::launch
