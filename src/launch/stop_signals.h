#pragma once
// The signals that stop a process that flies, in one place for `eamos run`, `launch`, `dex`
// and `sim-vehicle`: each ends the flight as Ctrl-C does (every drone's failsafe first, then
// the report), never the default action that would end the process with drones in the air.
#include <vector>

namespace eamos::launch {

/// SIGINT (Ctrl-C), SIGTERM (a service manager, kill), SIGHUP (the terminal or the SSH session
/// that started the process closed) and SIGQUIT (Ctrl-\). A SIGHUP that was ignored when the
/// process started (`nohup`) is left out: it stays ignored, as the user asked.
const std::vector<int>& stop_signals();

/// "SIGHUP" for SIGHUP, and so on for each stop signal.
const char* stop_signal_name(int signal);

/// Installs `handler` for every stop signal.
void on_stop_signals(void (*handler)(int));

/// SIGPIPE ignored: a reader of the output that goes away (`| head`, a pager closed) makes a
/// write fail instead of killing the process; the flight goes on to its end.
void ignore_broken_pipes();

}  // namespace eamos::launch
