#pragma once
// How a mission that is over without completing ends, in one place for the in-process runner
// (runner.cpp, every drone on one loop) and each drone's DEX process (src/launch): every
// engine halts and every drone is commanded its fleet failsafe before anything is recorded,
// then the run stays up until each drone's failsafe is over.
#include <functional>
#include <string>
#include <vector>

#include "dex/engine.h"
#include "dex/trace.h"
#include "fleet/fleet.h"
#include "mid/drone_api.h"
#include "mid/event_loop.h"

namespace eamos::dex {

/// What a failsafe ends in, and what needs none: down with its motors off.
inline bool down_and_disarmed(const mid::DroneState& s) { return s.landed && !s.armed; }

/// Mission seconds a run waits at most for a drone's failsafe to end once the mission is
/// abandoned; past it the drone is reported as it is then (a failsafe landing or return
/// that has not ended in ten minutes is stuck, and waiting longer only hides that).
inline constexpr double kFailsafeWaitLimitS = 600.0;

/// Mission seconds a drone must stay disarmed, though its autopilot does not report it on the
/// ground, before its failsafe counts as over: with its motors off nothing is left to
/// command (no autopilot arms again in the air), and the time lets a land detector that
/// lags the disarm say landed. PX4 SITL was seen reporting a vehicle it disarmed on the
/// ground during a takeoff as not landed for as long as it was watched.
inline constexpr double kDisarmedSettleS = 5.0;

/// Whether a drone in state `s`, whose fleet failsafe is `failsafe`, needs no more waiting
/// `waited_s` mission seconds after its mission was abandoned, `disarmed_s` of them seen
/// disarmed (0 while armed): down with its motors off; disarmed for kDisarmedSettleS
/// wherever its autopilot says it is; in the air with `hover` (it holds where it is from the
/// moment it is told: there is no end to wait for); its link lost (nothing can reach or
/// watch it; its autopilot's own link-loss failsafe flies it); or waited kFailsafeWaitLimitS.
/// In-process runs and each DEX end so.
bool failsafe_over(const mid::DroneState& s, fleet::Failsafe failsafe, double waited_s, double disarmed_s);

/// The mission was abandoned: makes `drone` safe with its fleet failsafe when it is in the air
/// or armed on the ground, then records a `failsafe` event (at mission time `t`) in `trace`
/// (may be null). A drone already landed and disarmed is left alone.
void enter_failsafe(mid::Drone& drone, const fleet::DroneSettings& settings, double t, const std::string& reason,
                    TraceSink* trace);
/// enter_failsafe in two steps, for callers with more to do between commanding and
/// recording (a trace write can block): true when a failsafe was commanded.
bool command_failsafe(mid::Drone& drone, const fleet::DroneSettings& settings);
void record_failsafe(const fleet::DroneSettings& settings, double t, const std::string& reason, TraceSink* trace);

/// One drone of a mission being abandoned, as the process that runs it holds it.
struct FailsafeDrone {
  Engine* engine;  ///< its engine (halted first: it starts nothing more)
  mid::Drone* drone;
  const fleet::DroneSettings* settings;  ///< its fleet settings: the failsafe, the name
};

/// Abandons the mission on `drones` at mission time `t`: halts every engine, commands every
/// drone's failsafe, runs `between` (the DEX's ABORT to the others and its log line: a DDS
/// write may block, the drones must not wait), and only then records each failsafe that
/// was commanded in `trace` (may be null). Safety first, words second.
void abandon_drones(const std::vector<FailsafeDrone>& drones, double t, const std::string& reason,
                    TraceSink* trace, const std::function<void()>& between = {});

/// Keeps looking at abandoned drones until each one's failsafe is over (failsafe_over),
/// then calls `on_over` once. The first look comes after the callbacks already queued on
/// the loop, the ends of the actions the failsafes cancelled among them, so those still
/// reach the trace; later looks come every `period_s` mission seconds. A drone that was
/// down and disarmed when the wait started (so no failsafe was commanded) and is seen armed
/// later gets its failsafe then, recorded in `trace` (may be null): an ARM the adapter had
/// sent for the mission may take effect after the abandonment (PX4 SITL armed two vehicles
/// so, and only its own auto-disarm stopped them). A pending look is cancelled when the
/// watch is destroyed.
class FailsafeWait {
 public:
  FailsafeWait(mid::EventLoop& loop, std::vector<FailsafeDrone> drones, double period_s,
               std::function<void()> on_over, TraceSink* trace = nullptr);
  ~FailsafeWait();
  FailsafeWait(const FailsafeWait&) = delete;
  FailsafeWait& operator=(const FailsafeWait&) = delete;

  /// Starts watching, counting the wait from now.
  void start();

 private:
  void look();
  /// Commands the failsafe of each drone seen armed that had none commanded.
  void fail_over_armed(double now);

  mid::EventLoop& loop_;
  std::vector<FailsafeDrone> drones_;
  double period_s_;
  std::function<void()> on_over_;
  TraceSink* trace_;
  double since_ = 0.0;
  std::vector<bool> commanded_;         ///< per drone: its failsafe was commanded (when not down and disarmed)
  std::vector<double> disarmed_since_;  ///< per drone: the first look that saw it disarmed; -1 armed
  mid::TimerId next_ = mid::kNoTimer;
};

}  // namespace eamos::dex
