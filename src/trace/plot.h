#pragma once
// A picture of one run (the paper's Figure 3): the drones' tracks seen from above, and a
// timeline per drone with a bar per action, coloured by how it ended. Plain SVG text.
#include <string>
#include <vector>

#include "dex/runner.h"
#include "dex/trace.h"

namespace eamos::trace {

/// Top panel: each drone's track in the x/y plane (equal scale, metres), grey on the
/// ground, solid in the air, start labelled with the drone's name, a black square where
/// it armed, a green diamond where it landed, the failsafe's part dashed red, an orange ring
/// where it gave way to another drone and a dot where it flew on. Middle panel:
/// every drone's altitude over mission time. Bottom panel: one row per drone over mission
/// time, a bar per action start (`data-action` attribute) from start to end, coloured by
/// outcome; a labelled tick per condition decision (in lanes, never overlapping); each
/// wait for another drone's trigger (class "wait": who, on whom, how long) with an arrow
/// from the sender; each failsafe phase hatched red. `events` is the run's trace.
/// A problem to show on the picture (`eamos verify`): a red ring at (x, y) on the map and a
/// red line at mission time t across the timeline, both labelled.
struct PlotMark {
  double t = 0.0;
  double x = 0.0, y = 0.0;  ///< m, mission frame
  std::string label;        ///< "separation", ...
};

/// Above this many drones the picture is a summary: thin tracks, the fleet's altitude range,
/// a band of how many drones are in each state over time, and rows only for the drones whose
/// action failed or that finished last (docs/trace.md, "The picture of a run").
constexpr std::size_t kPlotSummaryAbove = 40;

/// What plot_svg draws from, kept while a run flies: every event but telemetry (the tracks
/// come from the RunResult), and the messages between drones only up to kPlotSummaryAbove
/// drones: in one process a fleet-wide barrier of k drones is k² of them (52 million for a
/// 1,000-drone show, which held 19 GB), so the summary's rows show no waits.
class PlotTrace : public dex::TraceSink {
 public:
  explicit PlotTrace(std::size_t drones) : messages_(drones <= kPlotSummaryAbove) {}
  void record(const dex::TraceEvent& e) override {
    if (e.event == "telemetry" || (!messages_ && e.event == "message")) return;
    events.push_back(e);
  }
  bool takes_messages() const override { return messages_; }
  std::vector<dex::TraceEvent> events;

 private:
  bool messages_;
};

/// `caption`, when given, is a line under the title (which run of several this is).
std::string plot_svg(const dex::RunResult& run, const std::vector<dex::TraceEvent>& events,
                     const std::vector<PlotMark>& marks = {}, const std::string& caption = "");

}  // namespace eamos::trace
