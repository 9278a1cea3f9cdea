// `eamos run` / `eamos run --distributed` on a terminal: the real binary runs on a real
// pseudo-terminal (forkpty), and the test reads what it drew there — status lines per drone
// redrawn in place, not the live log's lines (which a pipe still gets: the other tests
// parse those).
#include <gtest/gtest.h>

#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <regex>
#include <string>
#include <vector>

namespace {

struct Screen {
  int status = -1;
  std::string bytes;  ///< everything the program wrote to its terminal
};

/// Runs `eamos args` with a pseudo-terminal as its standard output and error.
Screen run_on_terminal(const std::vector<std::string>& args) {
  Screen s;
  int master = -1;
  pid_t pid = forkpty(&master, nullptr, nullptr, nullptr);
  if (pid < 0) return s;
  if (pid == 0) {
    std::vector<char*> argv;
    std::string exe = EAMOS_BINARY;
    argv.push_back(exe.data());
    std::vector<std::string> copy = args;
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    setenv("TERM", "xterm", 1);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  char buf[4096];
  for (;;) {
    ssize_t n = read(master, buf, sizeof buf);
    if (n > 0) s.bytes.append(buf, n);
    else if (n < 0 && errno == EINTR) continue;
    else break;  // EIO: the program closed its side of the terminal (it exited)
  }
  close(master);
  int raw = 0;
  waitpid(pid, &raw, 0);
  s.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return s;
}

const std::string kListing2 = std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos";

void expect_status_lines_drawn_in_place(const Screen& s) {
  // Three status lines, moved back up over ("ESC [3F") and redrawn, ending at 100 %.
  EXPECT_NE(s.bytes.find("\x1b[3F"), std::string::npos) << s.bytes;
  EXPECT_NE(s.bytes.find("Drone1   [####################] 100%"), std::string::npos) << s.bytes;
  EXPECT_NE(s.bytes.find("done (2 not run)"), std::string::npos) << s.bytes;  // the If's other branch
  EXPECT_NE(s.bytes.find("Drone3   [####################] 100%"), std::string::npos) << s.bytes;
  // Under way, a drone's line names the action it runs now (first drawn when an action starts).
  EXPECT_TRUE(std::regex_search(s.bytes, std::regex(R"(Drone\d   \[[#.]{20}\] +\d+%  +[0-9.]+ s  Drone\d\.\w+\()")))
      << s.bytes;
  // Not the live log's line per event: that is for pipes.
  EXPECT_EQ(s.bytes.find("start     Drone1.Arm()"), std::string::npos) << s.bytes;
  // What ends the run still prints as a line.
  EXPECT_NE(s.bytes.find("mission     completed"), std::string::npos) << s.bytes;
}

TEST(Progress, RunOnATerminalRedrawsOneStatusLinePerDrone) {
  Screen s = run_on_terminal({"run", "-q", kListing2});
  ASSERT_EQ(s.status, 0) << s.bytes;
  expect_status_lines_drawn_in_place(s);
  // In virtual time deterministic: the first draw is at the first action's start.
  EXPECT_NE(s.bytes.find("Drone1   [....................]   0%      0.00 s  Drone1.Arm()"), std::string::npos)
      << s.bytes;
  EXPECT_NE(s.bytes.find("mission completed in 16.7 s (mission time)"), std::string::npos) << s.bytes;
}

TEST(Progress, DistributedRunOnATerminalShowsTheGroundsStatusLines) {
  std::string dir = testing::TempDir() + "eamos-progress-" + std::to_string(getpid());
  Screen s = run_on_terminal({"run", "-q", kListing2, "--distributed", "--insecure", "--speed", "5", "--domain",
                              "62", "--deploy-dir", dir});
  ASSERT_EQ(s.status, 0) << s.bytes;
  expect_status_lines_drawn_in_place(s);
}

}  // namespace
