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

/// For a process that flies, what the terminal and the shell may send to stop or kill it
/// without meaning to end the flight is ignored: SIGPIPE (a reader of the output that went
/// away, `| head`, a pager closed: the write fails and the flight goes on to its end), SIGTSTP
/// (Ctrl-Z would suspend it with every drone on its last command), SIGTTIN and SIGTTOU (a
/// background job that touches the terminal would be suspended too).
void keep_flying_through_the_terminal();

}  // namespace eamos::launch
