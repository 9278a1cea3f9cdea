#pragma once
// `eamos verify`: flies a compiled mission in the built-in simulator on virtual time, once
// per explored path, and checks every flight against the fleet's operating rules
// (fleet::Safety, geofences, sensor ranges): separation, geofence, battery reserve, speed
// and climb, occupied take-off and landing spots, the state at the end, waits that never
// end and actions the vehicle refuses. Each violation points at the source line of the
// action responsible and names the path (the condition outcomes) that leads to it.
#include <string>
#include <vector>

#include "dex/mission.h"
#include "dex/runner.h"
#include "dex/trace.h"
#include "graph/pipeline.h"

namespace eamos::verify {

struct VerifyOptions {
  int max_paths = 64;         ///< runs at most; exploration stops there (incomplete)
  bool jitter = false;        ///< also fly each path with every drone 10 % slower and faster
  double time_limit_s = 3600; ///< a run still going then: "never ends"
  /// Flights flown at once, each on its own thread; 0: one per core. The report is the same
  /// whatever the number.
  int jobs = 0;
};

/// One decision that made a path: condition `text` of `drone` (at line/col) went `value`.
struct Decision {
  std::string drone;
  int meg = 0;  ///< the condition's MEG id
  int line = 0, col = 0;
  std::string text;
  bool value = false;
  bool forced = false;  ///< false: the value the simulated sensors gave
};

/// A source position with a message: where a violation points, and its notes.
struct Located {
  int line = 0, col = 0;
  std::string message;
};

struct Violation {
  std::string kind;  ///< separation | geofence | battery | speed | climb | descent |
                     ///< occupied_home | airborne_at_end | armed_at_end | never_ends | action_failed
  double t = 0.0;    ///< mission seconds
  std::vector<std::string> drones;
  Located at;                  ///< the action responsible: "what; how to fix"
  std::vector<Located> notes;  ///< the other action involved, the values a wait last read
  std::vector<Decision> path;  ///< the condition outcomes of the run that found it
  std::string timing;          ///< "" nominal; else which drones flew slower or faster
  int paths_seen = 1;          ///< explored paths on which it happened
  std::string failure;         ///< action_failed: the uniform FailureReason ("refused", …), else ""
};

/// One flown path, as needed to fly it again: the outcomes it forced and its timing.
struct FlownPath {
  std::vector<std::pair<std::pair<int, int>, bool>> forced;  ///< (drone, condition MEG id) → outcome
  std::vector<double> factors;     ///< per drone: durations × factor
  std::vector<Decision> decisions; ///< the free conditions it met, as they went
  std::string timing;              ///< "" nominal
  int number = 0;                  ///< 1 for the first path flown
  int violations = 0;              ///< broken rules on it (each counted once)
};

struct VerifyReport {
  std::vector<Violation> violations;  ///< in source order
  FlownPath worst;                    ///< the path with the most violations (first flown on ties)
  int paths = 0;                      ///< runs flown
  int free_conditions = 0;            ///< conditions explored both ways
  int timing_conditions = 0;          ///< Ifs/Repeats/Dos that read a drone while it moved
  int timing_both_ways = 0;           ///< of those, seen both ways across the timings flown
  bool complete = false;              ///< every combination of outcomes was flown
  std::string error;                  ///< setup problem (nothing was flown)
};

/// Verifies `c` (a complete compilation) with `missions`, the drones' mission files as
/// read back from the deployed format (index order = fleet order).
VerifyReport verify(const graph::Compilation& c, const std::vector<dex::Mission>& missions,
                    const VerifyOptions& options = {});

/// GCC-style text: one `file:line:col: error:` per violation with its notes, then a
/// summary line (paths flown, complete or not).
std::string format_report(const graph::Compilation& c, const VerifyReport& r);
/// The same as JSON for tools.
std::string json_report(const graph::Compilation& c, const VerifyReport& r);

}  // namespace eamos::verify

namespace eamos::verify {

/// The picture of the worst path of `report` (the one with the most violations; the first
/// path when none has any) as `eamos run --plot` draws it, with each violation on that path as
/// a red mark where and when it happened, and a caption naming the path's combination of
/// condition outcomes and its timing.
std::string plot_worst_path(const graph::Compilation& c, const std::vector<dex::Mission>& missions,
                            const VerifyOptions& options, const VerifyReport& report);

/// A violation where it happened: the drone's last published position at that moment.
struct PlacedViolation {
  Violation violation;
  double x = 0.0, y = 0.0, z = 0.0;
};

/// The worst path flown again (the one --plot draws): its trace events and its violations.
struct WorstFlight {
  std::vector<dex::TraceEvent> events;
  std::vector<PlacedViolation> violations;  ///< in time order
  std::vector<dex::DroneSummary> drones;    ///< each drone's track: a sample per change of position or phase
};
WorstFlight fly_worst_path(const graph::Compilation& c, const std::vector<dex::Mission>& missions,
                           const VerifyOptions& options, const VerifyReport& report);

}  // namespace eamos::verify
