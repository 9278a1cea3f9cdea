#include "launch/spawn.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

extern char** environ;

namespace eamos::launch {

Child spawn(const std::vector<std::string>& argv, const std::string& log, std::string& error) {
  Child c;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  // The ground's own DDS sockets are not the child's business.
  posix_spawn_file_actions_addclosefrom_np(&actions, 3);
  // Its own process group: a Ctrl-C at the terminal reaches the ground, which aborts the
  // run so that every drone runs its failsafe, instead of killing every DEX mid-air.
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setpgroup(&attr, 0);
  sigset_t defaults;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  sigaddset(&defaults, SIGCHLD);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  int rc = posix_spawn(&c.pid, args[0], &actions, &attr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (rc != 0) {
    error = "cannot start " + argv[0] + ": " + std::strerror(rc);
    c.pid = -1;
  }
  return c;
}

void poll(Child& c) {
  if (c.pid <= 0 || c.exit_status) return;
  int status = 0;
  struct rusage usage {};
  pid_t r = wait4(c.pid, &status, WNOHANG, &usage);
  if (r < 0 && errno == ECHILD) {  // reaped elsewhere: it is gone, its status unknown
    c.exit_status = 255;
    return;
  }
  if (r != c.pid) return;
  c.cpu_s = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
            static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) / 1e6;
  c.max_rss_kb = usage.ru_maxrss;
  c.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

void reap(Child& c, double timeout_s) {
  auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!c.exit_status && c.pid > 0) {
    poll(c);
    if (c.exit_status) return;
    if (std::chrono::steady_clock::now() > until) {
      kill(c.pid, SIGKILL);
      int status = 0;
      waitpid(c.pid, &status, 0);
      c.exit_status = 128 + SIGKILL;
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

std::string self_exe() {
  char buf[4096];
  ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return "eamos";
  buf[n] = '\0';
  return buf;
}

}  // namespace eamos::launch
