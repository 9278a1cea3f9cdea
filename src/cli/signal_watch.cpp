#include "cli/signal_watch.h"

#include <pthread.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include "launch/stop_signals.h"

namespace eamos::cli {

namespace {

sigset_t watched() {
  sigset_t set;
  sigemptyset(&set);
  for (int s : launch::stop_signals()) sigaddset(&set, s);
  return set;
}

}  // namespace

SignalWatch::SignalWatch(std::function<void(const char*)> on_first) : on_first_(std::move(on_first)) {
  sigset_t set = watched();
  pthread_sigmask(SIG_BLOCK, &set, &old_mask_);
  thread_ = std::thread([this] { watch(); });
}

SignalWatch::~SignalWatch() {
  stopping_ = true;
  pthread_kill(thread_.native_handle(), SIGTERM);  // wakes sigwait; stopping_ says it is not a user's
  thread_.join();
  pthread_sigmask(SIG_SETMASK, &old_mask_, nullptr);
}

void SignalWatch::watch() {
  sigset_t set = watched();
  int seen = 0;
  for (;;) {
    int signal = 0;
    if (sigwait(&set, &signal) != 0) continue;
    if (stopping_) return;
    const char* name = launch::stop_signal_name(signal);
    if (++seen == 1) {
      on_first_(name);  // it says what the first signal does: that depends on when it came
      continue;
    }
    // Nothing more is commanded: a drone keeps doing what its failsafe told it.
    static const char kMessage[] = "eamos: interrupted again: exiting now, without waiting for the failsafe\n";
    [[maybe_unused]] ssize_t n = write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
    std::_Exit(128 + signal);
  }
}

}  // namespace eamos::cli
