#pragma once
// Child processes of `eamos launch`: one DEX per drone, its output in a log file.
#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

namespace eamos::launch {

struct Child {
  pid_t pid = -1;
  std::optional<int> exit_status;  ///< set once it ended: its exit code, or 128 + signal
  double cpu_s = 0.0;              ///< once ended: user + system CPU seconds it used
  long max_rss_kb = 0;             ///< once ended: its peak resident memory
};

/// Starts `argv` (argv[0] is the program path) with stdout and stderr appended to `log`;
/// pid -1 with `error` set on failure.
Child spawn(const std::vector<std::string>& argv, const std::string& log, std::string& error);
/// Updates `c.exit_status` if the child has ended; never blocks.
void poll(Child& c);
/// Waits for the child to end for up to `timeout_s`, then kills it (SIGKILL).
void reap(Child& c, double timeout_s);
/// This program's own path (/proc/self/exe), to start DEX processes of the same build.
std::string self_exe();

}  // namespace eamos::launch
