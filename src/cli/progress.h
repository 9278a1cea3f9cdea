#pragma once
// The live status of `eamos run` / `eamos launch` on a terminal: one line per drone (its
// current action, the mission time, how much of its actions is done), redrawn in place, so
// a long run shows where it is instead of scrolling thousands of lines by. What matters
// later (a failed action, a failsafe, the vehicle's own messages) still prints as a line
// above the status. Through a pipe the live log (dex::LiveLog) prints instead, unchanged.
#include <chrono>
#include <map>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "dex/mission.h"
#include "dex/trace.h"

namespace eamos::cli {

struct DroneProgress {
  std::string name;
  int actions = 0;               ///< action nodes the drone holds
  std::set<int> done;            ///< action nodes that ended at least once
  std::vector<std::string> running;  ///< texts of the actions running now, oldest first
  bool failsafe = false;
};

class ProgressDisplay : public dex::TraceSink {
 public:
  /// `missions`: every drone's, for its action count (fleet order).
  ProgressDisplay(std::ostream& out, const std::vector<dex::Mission>& missions);
  void record(const dex::TraceEvent& e) override;
  bool takes_messages() const override { return false; }
  /// Draws the final state and leaves the cursor below it (call once, after the run).
  void finish();

  /// One drone's status line as drawn (without colour or cursor movement).
  std::string line(const DroneProgress& d) const;

 private:
  void apply(const dex::TraceEvent& e);
  void draw();
  void print_above(const std::string& text);

  std::ostream& out_;
  std::vector<DroneProgress> drones_;
  std::map<std::string, int> index_;
  double now_ = 0.0;
  int drawn_ = 0;  ///< status lines on the screen now (0: none drawn yet)
  bool ended_ = false;
  bool completed_ = false;
  bool dirty_ = false;  ///< something changed since the last draw
  std::chrono::steady_clock::time_point last_draw_{};
};

/// True when standard output is a terminal (and TERM is not "dumb").
bool stdout_is_terminal();

}  // namespace eamos::cli
