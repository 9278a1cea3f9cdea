#include "launch/stop_signals.h"

#include <csignal>

namespace eamos::launch {

const std::vector<int>& stop_signals() {
  // Read once, before any handler of ours replaces the disposition the process started with.
  static const std::vector<int> signals = [] {
    struct sigaction hangup {};
    sigaction(SIGHUP, nullptr, &hangup);
    if (hangup.sa_handler == SIG_IGN) return std::vector<int>{SIGINT, SIGTERM, SIGQUIT};
    return std::vector<int>{SIGINT, SIGTERM, SIGHUP, SIGQUIT};
  }();
  return signals;
}

const char* stop_signal_name(int signal) {
  switch (signal) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    case SIGQUIT:
      return "SIGQUIT";
    default:
      return "a signal";
  }
}

void on_stop_signals(void (*handler)(int)) {
  for (int s : stop_signals()) std::signal(s, handler);
}

void keep_flying_through_the_terminal() {
  for (int s : {SIGPIPE, SIGTSTP, SIGTTIN, SIGTTOU}) std::signal(s, SIG_IGN);
}

}  // namespace eamos::launch
