#pragma once
// Runs the `eamos` binary under test (EAMOS_BINARY), or another program the tests build, the
// way a user would, for the tests that check commands end to end.
#include <sys/wait.h>

#include <cstdio>
#include <functional>
#include <string>

namespace eamos_test {

struct Output {
  int status = -1;
  std::string out;  ///< stdout and stderr together
};

/// Runs `program args` (stderr into stdout); `on_line`, if given, sees each output line as it
/// comes (and may act on it, e.g. kill a process the output names).
inline Output run_program(const std::string& program, const std::string& args,
                          const std::function<void(const std::string&)>& on_line = {},
                          const std::string& working_dir = "") {
  std::string cmd = program + " " + args + " 2>&1";
  // The working directory is quoted as a whole; callers pass paths of the test tree.
  if (!working_dir.empty()) cmd = "cd '" + working_dir + "' && " + cmd;
  Output r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  while (fgets(buf, sizeof buf, p)) {
    r.out += buf;
    if (on_line) on_line(buf);
  }
  int raw = pclose(p);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

#ifdef EAMOS_BINARY
/// Runs `eamos args`, as run_program.
inline Output run_eamos(const std::string& args, const std::function<void(const std::string&)>& on_line = {},
                        const std::string& working_dir = "") {
  return run_program(EAMOS_BINARY, args, on_line, working_dir);
}
#endif

}  // namespace eamos_test
