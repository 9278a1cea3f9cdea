#pragma once
// Inside the verifier: one flight of the mission (one explored path) and what was seen on
// it, and the checks that turn a flight into violations.
#include <limits>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "dex/runner.h"
#include "verify/verify.h"

namespace eamos::verify {

/// The mission and fleet every flight shares.
struct Setup {
  const graph::Compilation& c;
  const std::vector<dex::Mission>& missions;
  VerifyOptions options;
};

/// (drone index, condition MEG id) → the outcome a path forces on that condition.
using Assignment = std::map<std::pair<int, int>, bool>;

/// An action as it ran: from its start to its end (infinity when it never ended).
struct ActionRun {
  int drone = 0;
  const dex::Node* node = nullptr;
  mid::ActionRequest request;
  mid::DroneState state;  ///< at the start
  double start = 0.0;
  double end = std::numeric_limits<double>::infinity();
  std::string outcome;  ///< "" while running
  bool motion = false;
};

/// The last evaluation of one condition on one drone.
struct ConditionSeen {
  const dex::Node* node = nullptr;
  double t = 0.0;
  bool value = false;
  std::vector<std::pair<const dex::Expr*, double>> reads;  ///< each property read (Drone1.X) → its value
};

struct Flight {
  dex::RunResult result;
  std::vector<dex::TraceEvent> events;
  std::vector<ActionRun> actions;                      ///< in start order
  std::vector<std::vector<std::size_t>> actions_of;    ///< per drone: its runs in `actions`, in start order
  std::map<std::pair<int, int>, ConditionSeen> conditions;  ///< (drone, meg) → last seen
  std::vector<Decision> decisions;                     ///< free conditions, first evaluation each
  std::vector<std::pair<int, int>> decision_keys;      ///< (drone, meg) of each decision
  /// Conditions whose first outcome may hinge on other drones' timing (an If, Repeat or Do
  /// that read a drone while it was moving): (drone, meg) → {outcome, the moving drones read}.
  std::map<std::pair<int, int>, std::pair<bool, std::vector<int>>> timing_conditions;
  std::vector<double> factors;                         ///< per drone: durations × factor
  double abandoned_at = -1.0;                          ///< first failsafe; -1 none
};

/// Flies one path: conditions in `forced` take the given outcome (where the fleet's sensor
/// ranges allow it), every drone's actions take `factors[d]` times as long. `whole_trace`
/// keeps every trace event in `Flight::events` (for the picture and --trace); the checks need
/// none of them, and a flight of a hundred drones records tens of thousands.
Flight fly(const Setup& setup, const Assignment& forced, const std::vector<double>& factors, bool whole_trace = false);

/// Every violation of the rules on `f`, each with f's path.
std::vector<Violation> check_flight(const Setup& setup, const Flight& f);

/// The action of `drone` running at `t` (a motion action when one runs), or null.
const ActionRun* running_at(const Flight& f, int drone, double t);

/// "12.35 s", "3.1 m", "(1, 2, 3)": how the verifier prints numbers.
std::string seconds(double t);
std::string num(double v);
std::string point(double x, double y, double z);

}  // namespace eamos::verify
