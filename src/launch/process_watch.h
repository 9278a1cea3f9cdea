#pragma once
// Wakes the ground's event loop when one of the DEX processes it started ends or a signal
// (Ctrl-C, TERM) comes, so that the ground waits for events instead of looking at its
// children every few milliseconds. One thread, blocked in poll(2) on a pidfd per child and
// a pipe the signal handler writes to.
#include <sys/types.h>

#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace eamos::launch {

class ProcessWatch {
 public:
  /// `wake` runs on the watch's thread when something happened: it must only post to the
  /// loop, which then looks at what (spawn.h's poll, the signal flag).
  explicit ProcessWatch(std::function<void()> wake);
  ~ProcessWatch();
  ProcessWatch(const ProcessWatch&) = delete;
  ProcessWatch& operator=(const ProcessWatch&) = delete;

  /// Watches `pid`, before or after start() (DEXes started in waves); false when the kernel
  /// has no pidfds for it, and then the caller must look at that child on a timer of its own.
  bool watch(pid_t pid);
  /// Starts the thread; from now on signal_arrived() wakes it.
  void start();
  /// Async-signal-safe: for the process's SIGINT/SIGTERM handler.
  static void signal_arrived();

 private:
  void run();

  std::function<void()> wake_;
  int pipe_[2] = {-1, -1};
  std::mutex mutex_;  ///< pidfds_: watch() adds while the thread polls
  std::vector<int> pidfds_;
  std::thread thread_;
};

}  // namespace eamos::launch
