#pragma once
// `eamos dex DIR/<drone>`: one drone's DEX as its own process, the deployment package's
// entry point (paper, section V). It loads the drone's mission file, makes the drone from
// the Adapter Space, joins the DDS domain and says READY; when the ground's start barrier
// passes it runs the mission in real time, exchanging triggers and telemetry with the
// other DEXes directly. No node is central during the mission: a failure anywhere is
// broadcast as ABORT and every drone runs its failsafe; the lead drone (holder of the end
// node) declares the mission finished once every drone is idle and nothing is in flight.
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "mid/adapter_registry.h"
#include "transport/dds_node.h"

namespace eamos::launch {

/// The default of DexProcessOptions::unready_limit_s: ten seconds short of Cyclone's
/// handshake timeout, for a DEX that started its handshakes a little after joining.
inline constexpr double kSecureUnreadyLimitS = transport::kHandshakeGiveUpS - 10.0;

/// How often a DEX publishes its drone's state to the others by default: every change (the
/// simulator's 20 Hz while moving) up to kFullRateDrones drones; beyond, the fleet's
/// telemetry grows with the square of its size (every drone's state to every other drone),
/// so the rate falls with it: 20 Hz * (kFullRateDrones / drones)^2, at least 1 Hz.
inline constexpr int kFullRateDrones = 20;
inline constexpr double kFullStateRateHz = 20.0;
double state_rate_for(int drones);

/// Wall seconds between two statuses of a DEX that differ only in their trigger counters:
/// 0 (every change) up to kFullRateDrones drones; beyond, a quarter of the liveliness lease.
/// Every drone receives every other drone's arrival at a barrier, and each received one
/// changes its counters: published at every change, a barrier of k drones would send
/// k(k - 1) statuses to k readers each. The lead's termination waves are answered at once
/// whatever this says (launch/termination.h); the newest counters always go out at the end
/// of the gap, so nothing the lead or a FINISHED waits for is lost, only coalesced.
double counters_gap_for(int drones, double lease_s);

/// How a status differs from the one published before it.
enum class StatusChange { none, counters, other };
StatusChange status_change(const transport::StatusSample& before, const transport::StatusSample& now);

struct DexProcessOptions {
  std::string folder;             ///< the drone's deployment folder (holds mission.json)
  transport::DdsOptions dds;
  double speed = 1.0;             ///< mission seconds per wall second; must match the ground's
  double start_timeout_s = 0.0;   ///< give up when no start came by then; 0 = wait for ever
  double time_limit_s = 3600.0;   ///< a mission still running then fails
  std::string trace_file;         ///< the drone's own JSONL trace; "" = none
  /// The `eamos launch` that started this DEX: its READY says so and it takes a START only
  /// from that launch. 0: started on its own; any launch may start it (once).
  std::uint64_t launch_id = 0;
  bool log = true;                ///< live log on `out`
  /// Without DDS Security even when the folder holds credentials (docs/security.md).
  bool insecure = false;
  /// Mission seconds: a trigger or cancel received later than this after it was sent fails
  /// the mission (this drone's failsafe, ABORT naming the message). 0 = no bound.
  double max_trigger_latency_s = 0.0;
  /// With DDS Security: wall seconds after joining the domain by which every other drone
  /// must have been heard from (all its handshakes done); otherwise the DEX leaves with an
  /// error before Cyclone's handshake timeout (transport::kHandshakeGiveUpS).
  double unready_limit_s = kSecureUnreadyLimitS;
  /// Drones (by name) whose DEX starts after this one (`eamos launch`'s later waves): not
  /// waited for within unready_limit_s. A handshake begins when the later of its two DEXes
  /// joins, so that one's own limit bounds it, however long the fleet takes to start.
  std::vector<std::string> later_drones;
  /// Times per wall second at most that this drone's state goes to the other drones (the
  /// newest state, never later than one period); 0: state_rate_for(the fleet's size).
  double state_rate_hz = 0.0;
};

/// Runs the process; returns its exit status: 0 when the mission completed, 1 otherwise
/// (bad folder, no start, failed or abandoned mission).
int run_dex_process(const DexProcessOptions& options, const mid::AdapterRegistry& adapters,
                    std::ostream& out, std::ostream& err);

}  // namespace eamos::launch
