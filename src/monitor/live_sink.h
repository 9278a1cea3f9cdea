#pragma once
// Feeds a running mission's trace events to the monitor's server as they happen: each event
// is written exactly as the JSONL trace writes it (dex/trace_writers.h), so the live page and
// a replay of the trace file see the same lines.
#include <mutex>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "dex/trace_writers.h"
#include "monitor/server.h"

namespace eamos::monitor {

/// Above this many drones (the page's lanes are then a canvas, with no trigger arrows) the
/// page gets no messages between drones, which in one process are k² per fleet-wide barrier
/// of k drones (a million at 1,000 drones), and each drone's telemetry at most once per
/// kThinTelemetryPeriod mission seconds (and whenever it arms, disarms, takes off or lands;
/// the map interpolates between samples). The trace file keeps every event.
constexpr std::size_t kThinTelemetryAbove = 60;
constexpr double kThinTelemetryPeriod = 1.0;

class LiveSink : public dex::TraceSink {
 public:
  /// `fleet`: the drones' names by index, which message events name their ends by.
  explicit LiveSink(MonitorServer& server, std::vector<std::string> fleet = {})
      : server_(server), thin_(fleet.size() > kThinTelemetryAbove), writer_(buffer_, std::move(fleet)) {}
  void record(const dex::TraceEvent& e) override;
  bool takes_messages() const override { return !thin_; }

 private:
  struct Sent {
    double t;
    bool armed, landed;
  };
  bool skip(const dex::TraceEvent& e);  ///< an event a large fleet's page does without

  MonitorServer& server_;
  bool thin_;
  std::unordered_map<std::string, Sent> last_sent_;  ///< per drone: its last telemetry passed on
  std::mutex mutex_;  // a distributed run's ground may record from several threads
  std::ostringstream buffer_;
  dex::JsonlTrace writer_;
};

}  // namespace eamos::monitor
