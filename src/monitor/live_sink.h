#pragma once
// Feeds a running mission's trace events to the monitor's server as they happen: each event
// is written exactly as the JSONL trace writes it (dex/trace_writers.h), so the live page and
// a replay of the trace file see the same lines.
#include <mutex>
#include <sstream>

#include "dex/trace_writers.h"
#include "monitor/server.h"

namespace eamos::monitor {

class LiveSink : public dex::TraceSink {
 public:
  explicit LiveSink(MonitorServer& server) : server_(server), writer_(buffer_) {}
  void record(const dex::TraceEvent& e) override;

 private:
  MonitorServer& server_;
  std::mutex mutex_;  // a distributed run's ground may record from several threads
  std::ostringstream buffer_;
  dex::JsonlTrace writer_;
};

}  // namespace eamos::monitor
