#include "monitor/live_sink.h"

namespace eamos::monitor {

void LiveSink::record(const dex::TraceEvent& e) {
  std::lock_guard<std::mutex> lock(mutex_);
  writer_.record(e);
  std::string line = buffer_.str();
  buffer_.str("");
  while (!line.empty() && line.back() == '\n') line.pop_back();
  server_.append(std::move(line));
}

}  // namespace eamos::monitor
