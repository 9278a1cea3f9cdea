#include "launch/process_watch.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>

namespace eamos::launch {

namespace {
// The write end of the running watch's pipe, for the signal handler (-1: none).
std::atomic<int> g_wake_fd{-1};
constexpr char kStop = 'q';
constexpr char kSignal = 's';
constexpr char kRescan = 'r';  // a child was added: poll its pidfd too
}  // namespace

ProcessWatch::ProcessWatch(std::function<void()> wake) : wake_(std::move(wake)) {
  if (pipe2(pipe_, O_CLOEXEC | O_NONBLOCK) != 0) pipe_[0] = pipe_[1] = -1;
}

ProcessWatch::~ProcessWatch() {
  if (thread_.joinable()) {
    g_wake_fd = -1;
    char stop = kStop;
    while (write(pipe_[1], &stop, 1) < 0 && errno == EINTR) {
    }
    thread_.join();
  }
  for (int fd : pidfds_)
    if (fd >= 0) close(fd);
  for (int fd : pipe_)
    if (fd >= 0) close(fd);
}

bool ProcessWatch::watch(pid_t pid) {
  int fd = static_cast<int>(syscall(SYS_pidfd_open, pid, 0));
  if (fd < 0) return false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pidfds_.push_back(fd);
  }
  char rescan = kRescan;
  if (thread_.joinable()) (void)!write(pipe_[1], &rescan, 1);  // a full pipe already wakes it
  return true;
}

void ProcessWatch::start() {
  if (pipe_[0] < 0) return;
  g_wake_fd = pipe_[1];
  thread_ = std::thread([this] { run(); });
}

void ProcessWatch::signal_arrived() {
  int fd = g_wake_fd.load();
  char s = kSignal;
  if (fd >= 0) (void)!write(fd, &s, 1);  // a full pipe already holds a wake-up
}

void ProcessWatch::run() {
  for (;;) {
    std::vector<pollfd> fds{{pipe_[0], POLLIN, 0}};
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (int fd : pidfds_)
        if (fd >= 0) fds.push_back({fd, POLLIN, 0});
    }
    if (::poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      return;
    }
    bool woke = false;
    if (fds[0].revents) {
      char buf[64];
      ssize_t n;
      while ((n = read(pipe_[0], buf, sizeof buf)) > 0)
        for (ssize_t i = 0; i < n; ++i) {
          if (buf[i] == kStop) return;
          if (buf[i] == kSignal) woke = true;
        }
    }
    // A pidfd stays readable once its process ended: it is watched no more.
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (std::size_t i = 1; i < fds.size(); ++i)
        if (fds[i].revents)
          for (int& fd : pidfds_)
            if (fd == fds[i].fd) {
              close(fd);
              fd = -1;
              woke = true;
            }
    }
    if (woke) wake_();
  }
}

}  // namespace eamos::launch
