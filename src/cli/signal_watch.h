#pragma once
// Ctrl-C, SIGTERM, a hangup or Ctrl-\ during `eamos run` (launch/stop_signals.h): the first
// abandons the mission into the failsafe (the run still lands every drone and writes its
// report), a second exits at once.
#include <atomic>
#include <functional>
#include <thread>

#include <signal.h>

namespace eamos::cli {

class SignalWatch {
 public:
  /// Blocks the stop signals in this thread and every thread started after it (so the
  /// MAVLink and DDS threads never take them) and waits for them on a thread of its own,
  /// which calls `on_first` with the first signal's name ("SIGINT"; it tells the user what
  /// that signal does) and exits the process with 128 + signal on the second. Construct it
  /// before any other thread starts.
  explicit SignalWatch(std::function<void(const char* name)> on_first);
  ~SignalWatch();
  SignalWatch(const SignalWatch&) = delete;
  SignalWatch& operator=(const SignalWatch&) = delete;

 private:
  void watch();

  std::function<void(const char*)> on_first_;
  sigset_t old_mask_{};
  std::atomic<bool> stopping_{false};
  std::thread thread_;
};

}  // namespace eamos::cli
