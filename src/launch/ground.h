#pragma once
// `eamos launch DIR`: the ground process. It starts one DEX process per drone on this
// machine (or waits for DEXes started elsewhere), holds the start barrier until every
// drone is READY with the same mission hash, starts them together, and collects their
// trace, telemetry and final status into one report like `eamos run`'s. It takes no part
// in the mission itself: the DEXes trigger, cancel and abort among themselves.
#include <iosfwd>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dex/runner.h"
#include "dex/trace.h"
#include "transport/dds_node.h"

namespace eamos::launch {

struct LaunchOptions {
  std::string dir;                  ///< deployment folder (manifest.json, one folder per drone)
  transport::DdsOptions dds;
  double speed = 1.0;               ///< mission seconds per wall second, for every DEX
  /// Wall seconds to wait for every READY; 0: barrier_timeout_for(drones, secure).
  double barrier_timeout_s = 0.0;
  double time_limit_s = 3600.0;     ///< mission seconds, passed to every DEX
  double start_delay_s = 0.5;       ///< wall seconds between START and mission time 0
  /// DEX processes started at once; the next wave starts when the ground has heard from
  /// every DEX started before it. 0: start_wave_for(the drones started here, secure).
  int start_wave = 0;
  /// Passed to every DEX started here (DexProcessOptions::state_rate_hz); 0: its default.
  double state_rate_hz = 0.0;
  std::vector<std::string> local;   ///< drones to start here; empty = all of them (unless remote_only)
  bool remote_only = false;         ///< start none here: every DEX runs elsewhere (on its drone)
  std::string exe;                  ///< the eamos program for DEX processes ("" = this one)
  /// Wall seconds the ground waits, after a drone was lost, for it to come back and report
  /// its final state (a network cut that ends); after that its state is reported unknown.
  double final_state_timeout_s = 10.0;
  /// Without DDS Security, for the ground and every DEX it starts (docs/security.md).
  bool insecure = false;
  double telemetry_hz = 5.0;  ///< telemetry events per drone per mission second in the trace; 0 = none
  /// Mission seconds: a trigger or cancel received later than this after it was sent is a
  /// warning on the console and in the summary.
  double latency_warn_s = dex::kDefaultLatencyWarnS;
  /// Mission seconds: a trigger or cancel later than this fails the mission: passed to every
  /// DEX started here (the receiving DEX abandons into the failsafe); for a DEX started
  /// elsewhere the ground writes the ABORT when it hears of the message. 0 = no bound.
  double max_trigger_latency_s = 0.0;
};

/// With DDS Security, the longest start barrier: every DEX it started (whose start timeout
/// is the barrier's plus 5 s) and the ground itself leave the domain before Cyclone gives
/// up a pending handshake (transport::kHandshakeGiveUpS), which can crash Debian's build.
inline constexpr double kMaxSecureBarrierS = 85.0;

/// DEX processes `eamos launch` starts at once by default, with and without DDS Security.
inline constexpr int kSecureStartWave = 10;
inline constexpr int kInsecureStartWave = 25;
/// Beyond this many drones, DDS Security starts in waves of kLargeSecureStartWave: each wave
/// joins a fleet that keeps all its pairs of participants in touch, and on a 2-core host the
/// eighth wave of 10 joining 70 secure DEXes did not finish in 85 s, waves of 5 did
/// (docs/performance.md, "Many DEX processes on one host").
inline constexpr int kLargeSecureFleet = 50;
inline constexpr int kLargeSecureStartWave = 5;

/// The default wave of DEX processes started together: the whole fleet up to the default
/// wave size, otherwise waves of that size.
int start_wave_for(int drones, bool secure);

/// The start barrier's default: 30 s, and half a second more per drone beyond 20 (each
/// participant discovers and, with DDS Security, authenticates every other one); with DDS
/// Security at most kMaxSecureBarrierS.
double barrier_timeout_for(int drones, bool secure);

struct LaunchResult {
  dex::RunResult run;                   ///< as `eamos run` reports it
  std::vector<dex::TraceEvent> events;  ///< every drone's events, by time
  nlohmann::ordered_json header;        ///< the trace's first line (docs/trace.md)
  std::vector<std::string> fleet;       ///< drone names by index
  std::uint64_t run_id = 0;
};

/// Runs the mission in DIR; `live` (may be null) sees events as they arrive. Returns the
/// exit status: 0 when the mission completed and every DEX exited cleanly.
int launch(const LaunchOptions& options, dex::TraceSink* live, LaunchResult& result, std::ostream& out,
           std::ostream& err);

}  // namespace eamos::launch
