#pragma once
// Feeds a running mission's trace events to the monitor's server as they happen: each event
// is written exactly as the JSONL trace writes it (dex/trace_writers.h), so the live page and
// a replay of the trace file see the same lines.
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "dex/trace_writers.h"
#include "monitor/server.h"

namespace eamos::monitor {

class LiveSink : public dex::TraceSink {
 public:
  /// `fleet`: the drones' names by index, which message events name their ends by.
  explicit LiveSink(MonitorServer& server, std::vector<std::string> fleet = {})
      : server_(server), writer_(buffer_, std::move(fleet)) {}
  void record(const dex::TraceEvent& e) override;

 private:
  MonitorServer& server_;
  std::mutex mutex_;  // a distributed run's ground may record from several threads
  std::ostringstream buffer_;
  dex::JsonlTrace writer_;
};

}  // namespace eamos::monitor
