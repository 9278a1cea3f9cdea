#pragma once
// Starts the `eamos` binary under test (EAMOS_BINARY) as a child whose pid the test knows,
// so it can signal it while reading its output line by line, as a terminal or `| tee`
// would see it. For runs that only need the end result, run_eamos.h is simpler.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

extern char** environ;

namespace eamos_test {

struct EamosProcess {
  pid_t pid = -1;
  FILE* out = nullptr;  ///< the child's stdout and stderr, one pipe
  std::string seen;     ///< every line read so far
};

/// Starts `eamos args...` with stdout and stderr on a pipe; pid is -1 when it could not.
inline EamosProcess start_eamos(const std::vector<std::string>& args) {
  EamosProcess p;
  int fds[2];
  if (pipe(fds) != 0) return p;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDERR_FILENO);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  posix_spawn_file_actions_addclose(&actions, fds[1]);
  std::vector<std::string> all = {EAMOS_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  if (posix_spawn(&p.pid, EAMOS_BINARY, &actions, nullptr, argv.data(), environ) != 0) p.pid = -1;
  posix_spawn_file_actions_destroy(&actions);
  close(fds[1]);
  p.out = fdopen(fds[0], "r");
  return p;
}

/// Reads lines until one contains `text` (true) or the output ends (false).
inline bool read_until(EamosProcess& p, const std::string& text) {
  char buf[4096];
  while (p.out && fgets(buf, sizeof buf, p.out)) {
    p.seen += buf;
    if (std::string(buf).find(text) != std::string::npos) return true;
  }
  return false;
}

/// True while the child has not exited (it may still be writing).
inline bool still_running(const EamosProcess& p) {
  siginfo_t info{};
  // WNOWAIT: look without reaping, so wait_exit still gets the status.
  return waitid(P_PID, static_cast<id_t>(p.pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == 0;
}

struct Exit {
  bool exited = false;  ///< by exit(), not killed by a signal
  int status = -1;      ///< exit status, or the signal that killed it
};

/// Reads the rest of the output and waits for the child to end.
inline Exit wait_exit(EamosProcess& p) {
  read_until(p, std::string(1, '\0'));  // nothing matches: read to the end
  if (p.out) fclose(p.out);
  p.out = nullptr;
  int raw = 0;
  Exit e;
  if (waitpid(p.pid, &raw, 0) != p.pid) return e;
  e.exited = WIFEXITED(raw);
  e.status = e.exited ? WEXITSTATUS(raw) : (WIFSIGNALED(raw) ? WTERMSIG(raw) : -1);
  return e;
}

}  // namespace eamos_test
