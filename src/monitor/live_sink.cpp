#include "monitor/live_sink.h"

#include <chrono>

namespace eamos::monitor {

void LiveSink::record(const dex::TraceEvent& e) {
  // Stamped as it is handed over, before any wait for the lock: a page's latency counts from
  // the moment the mission emitted the event (docs/monitor.md).
  double emitted_ms = std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch()).count();
  std::lock_guard<std::mutex> lock(mutex_);
  writer_.record(e);
  std::string line = buffer_.str();
  buffer_.str("");
  while (!line.empty() && line.back() == '\n') line.pop_back();
  server_.append(std::move(line), emitted_ms);
}

}  // namespace eamos::monitor
