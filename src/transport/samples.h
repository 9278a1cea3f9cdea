#pragma once
// The DDS samples as C++ values (the IDL's C structs stay inside the transport): what a
// DEX process and the ground process exchange besides dex::Message and dex::Telemetry.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dex/bridge.h"
#include "dex/failure.h"
#include "dex/trace.h"
#include "mid/drone_api.h"

namespace eamos::transport {

inline constexpr int kGround = -1;  ///< the `drone` of what the ground process writes

/// TriggerSample::to of a sample for every drone it concerns (an arrival at a sync point).
inline constexpr int kEveryDrone = -1;

struct TriggerSample {
  std::uint64_t run_id = 0;
  int to = 0;  ///< receiving drone, or kEveryDrone
  std::uint64_t seq = 0;  ///< per sender, from 1
  dex::Message message;   ///< carries the mission hash and the sender
};

struct TelemetrySample {
  std::uint64_t run_id = 0;
  dex::Telemetry telemetry;
};

enum class LifecycleKind { ready, start, abort, finished, refused };
const char* lifecycle_name(LifecycleKind k);

struct LifecycleSample {
  std::string mission_hash;
  int drone = kGround;  ///< sender
  LifecycleKind kind = LifecycleKind::ready;
  std::uint64_t run_id = 0;
  std::uint64_t nonce = 0;              ///< ready: the sending process, one per process start
  std::uint64_t launch_id = 0;          ///< ready, start, refused: the launch (0: none)
  std::int64_t start_at_ns = 0;         ///< start: Unix time of mission time 0
  double speed = 1.0;                   ///< start, ready: mission seconds per wall second
  double t = 0.0;                       ///< abort, finished: mission time
  std::vector<std::uint64_t> nonces;    ///< start: per drone, the process that was ready
  std::string reason;                   ///< abort, refused
  std::optional<dex::Failure> failure;  ///< abort caused by a failed action
  /// ready: the drone's declared home (x, y) and where its vehicle stands on the Earth, if it
  /// reports that; the ground compares the drones' (mid/home_check.h) before the start.
  std::optional<mid::GlobalFix> fix;
  double home_x = 0.0;
  double home_y = 0.0;
  double home_tolerance = fleet::kDefaultHomeToleranceM;
};

/// failsafe: abandoned, the failsafe runs; failed: abandoned, the failsafe ended (final state).
enum class Phase { waiting, running, completed, failed, failsafe };
const char* phase_name(Phase p);

struct StatusSample {
  std::string mission_hash;
  int drone = 0;
  std::uint64_t run_id = 0;
  std::uint64_t nonce = 0;     ///< the writing process, as in its READY
  Phase phase = Phase::waiting;
  bool busy = false;
  bool end_reached = false;
  std::uint64_t sent = 0;      ///< triggers sent
  std::uint64_t received = 0;  ///< triggers of this run received
  std::uint64_t activations = 0;
  /// Termination waves (launch/termination.h): the lead's asks for this wave, another
  /// drone's answers it.
  std::uint64_t wave = 0;
  double since = 0.0;          ///< mission time the drone entered its current busy/idle state
  /// While waiting for the start: how many other drones this DEX has heard from (the
  /// ground starts the next wave of DEXes once every DEX has heard from all started before).
  int heard = 0;
  mid::DroneState state;       ///< sensors not included
};

struct TraceSample {
  std::string mission_hash;
  std::uint64_t run_id = 0;
  int drone = 0;
  std::uint64_t seq = 0;  ///< per drone, from 1: the drone's own order of events
  dex::TraceEvent event;
};

/// What a received sample is checked against.
struct WireLimits {
  /// The mission's drone count: drone indices must be below it. 0: not known (a node
  /// without a mission, in tests), then below kMaxWireDrones.
  int drones = 0;
};
inline constexpr int kMaxWireDrones = 100000;
inline constexpr std::size_t kMaxWireHash = 64;        ///< a SHA-256 in hex
inline constexpr std::size_t kMaxWireName = 256;       ///< sensor, event, action names
inline constexpr std::size_t kMaxWireText = 4096;      ///< reasons, labels
inline constexpr std::size_t kMaxWireSensors = 64;     ///< fleet::kMaxSensors

}  // namespace eamos::transport
