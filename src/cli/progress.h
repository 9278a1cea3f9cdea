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
  int last = -1;                 ///< the drone's node that ended last (index into its mission)
};

/// Enough of a drone's mission to say on whom it waits: its nodes by MEG id, the nodes each
/// one's end lets start, and what each node needs from other drones.
struct WaitGraph {
  std::vector<int> meg;                      ///< node → MEG id
  std::vector<int> holder;                   ///< node → the drone that holds it
  std::vector<std::vector<int>> next;        ///< this drone's node → the nodes its end may start (any drone's)
  std::vector<std::vector<std::pair<int, int>>> needs;  ///< node → (drone, MEG id) ends it waits for
  std::vector<std::vector<int>> own_before;  ///< node → this drone's nodes with an exec arc into it
  std::vector<std::vector<int>> sync;        ///< sync point → other drones that must arrive
  std::map<int, int> node_of;                ///< MEG id → this drone's node
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
  /// Every drone's status line as it stands now (fleet order).
  std::vector<std::string> lines() const;
  /// "waiting for Drone3", "waiting until Drone1.X() >= 4.5", or "waiting": what an idle drone waits on.
  std::string waiting_text(const DroneProgress& d) const;
  /// The drones (or a condition) the nodes `d` can start next still need; false when none.
  bool pending(int self, const std::vector<int>& nodes, std::set<int>& on, std::string& until) const;

 private:
  void apply(const dex::TraceEvent& e);
  void draw();
  void print_above(const std::string& text);

  std::ostream& out_;
  std::vector<DroneProgress> drones_;
  std::vector<WaitGraph> graphs_;          ///< per drone, fleet order
  std::set<std::pair<int, int>> ended_nodes_;
  std::map<int, std::string> false_conditions_;  ///< MEG id → text of a condition last found false    ///< (drone, MEG id) of every node that ended at least once
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
