#include "monitor/live_sink.h"

#include <chrono>

namespace eamos::monitor {

void LiveSink::record(const dex::TraceEvent& e) {
  // Stamped as it is handed over, before any wait for the lock: a page's latency counts from
  // the moment the mission emitted the event (docs/monitor.md).
  double emitted_ms = std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch()).count();
  std::lock_guard<std::mutex> lock(mutex_);
  if (skip(e)) return;
  writer_.record(e);
  std::string line = buffer_.str();
  buffer_.str("");
  while (!line.empty() && line.back() == '\n') line.pop_back();
  server_.append(std::move(line), emitted_ms);
}

bool LiveSink::skip(const dex::TraceEvent& e) {
  if (!thin_) return false;
  if (e.event == "message") return true;
  if (e.event != "telemetry" || !e.state) return false;
  Sent now{e.t, e.state->armed, e.state->landed};
  auto [at, first] = last_sent_.emplace(e.drone, now);
  if (first) return false;
  Sent& last = at->second;
  if (now.armed == last.armed && now.landed == last.landed && e.t - last.t < kThinTelemetryPeriod - 1e-9) return true;
  last = now;
  return false;
}

}  // namespace eamos::monitor
