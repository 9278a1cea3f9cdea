#pragma once
// Hands what DDS threads receive to a process's event loop. Before the mission starts
// there is no running loop yet: telemetry is kept (newest per drone) so the engine's
// board holds every drone's state before its first step, and anything else waits in
// arrival order until the loop takes over.
#include <functional>
#include <map>
#include <mutex>
#include <vector>

#include "mid/event_loop.h"
#include "transport/samples.h"

namespace eamos::launch {

class Inbox {
 public:
  void deliver(std::function<void()> fn) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (loop_)
      loop_->post(std::move(fn));
    else
      early_.push_back(std::move(fn));
  }
  /// Telemetry before the start is only kept; afterwards `fn` runs on the loop.
  void deliver_telemetry(const transport::TelemetrySample& s, std::function<void()> fn) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (loop_)
      loop_->post(std::move(fn));
    else
      latest_[s.telemetry.from] = s;
  }
  /// Newest telemetry per drone received so far (before attach).
  std::map<int, transport::TelemetrySample> latest() {
    std::lock_guard<std::mutex> lock(mutex_);
    return latest_;
  }
  /// From now on input goes to `loop`: `seed` gets the kept telemetry first (on this
  /// thread, before the loop runs), then the early input is posted in arrival order.
  void attach(mid::EventLoop& loop, const std::function<void(const transport::TelemetrySample&)>& seed) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [from, s] : latest_) seed(s);
    for (auto& fn : early_) loop.post(std::move(fn));
    early_.clear();
    loop_ = &loop;
  }

 private:
  std::mutex mutex_;
  mid::EventLoop* loop_ = nullptr;
  std::vector<std::function<void()>> early_;
  std::map<int, transport::TelemetrySample> latest_;
};

}  // namespace eamos::launch
