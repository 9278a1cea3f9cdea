// What a DEX process costs while a mission runs: a drone waiting at a barrier wakes only
// for its heartbeat and for what it receives, not on a timer of its own; its memory stays
// flat however many barriers and triggers the mission goes through. Real `eamos launch`
// and `eamos dex` processes on loopback, domains 46-47. Nothing here sleeps: the tests
// act on the ground's output lines and wait for the processes to end.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "support/run_eamos.h"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using eamos_test::Output;
using eamos_test::run_eamos;

std::string mission(const std::string& name) { return std::string(EAMOS_TEST_DATA) + "/missions/" + name; }

/// Voluntary context switches of `pid`'s main thread (a DEX's event loop): how often it
/// went to sleep, i.e. woke up. -1 when the process is gone.
long loop_wakeups(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("voluntary_ctxt_switches:", 0) == 0) return std::stol(line.substr(24));
  return -1;
}

/// The pid the ground printed for `drone`'s DEX, or -1.
pid_t dex_pid(const std::string& out, const std::string& drone) {
  std::string key = "started the DEX of " + drone + " (pid ";
  auto at = out.find(key);
  return at == std::string::npos ? -1 : std::stoi(out.substr(at + key.size()));
}

/// `eamos args…` started in the background, its output in `log`.
pid_t start_eamos(const std::vector<std::string>& args, const fs::path& log) {
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&files, 1, 2);
  std::vector<std::string> all = {EAMOS_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  if (posix_spawn(&pid, EAMOS_BINARY, &files, nullptr, argv.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&files);
  return pid;
}

struct Ended {
  int status = -1;
  long peak_rss_kb = 0;
};

Ended wait_for(pid_t pid) {
  Ended e;
  int raw = 0;
  rusage usage{};
  if (wait4(pid, &raw, 0, &usage) != pid) return e;
  e.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  e.peak_rss_kb = usage.ru_maxrss;
  return e;
}

class DexResources : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eamos-dexres-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  fs::path compile(const std::string& name) {
    Output c = run_eamos("compile -q " + mission(name) + " -o " + (dir_ / "deploy").string() + " --insecure");
    EXPECT_EQ(c.status, 0) << c.out;
    return dir_ / "deploy";
  }
  fs::path dir_;
};

TEST_F(DexResources, ADexWaitingAtABarrierWakesOnlyForItsHeartbeatAndWhatItReceives) {
  fs::path deploy = compile("barrier_wait.eamos");
  // Fast waits at the PAR boundary, disarmed, while Slow hovers 60 mission s (6 wall s at
  // --speed 10). Its loop then wakes for its heartbeat (a quarter of the 2 s lease: 12
  // times) and for each telemetry sample of Slow (1 Hz of mission time while it hovers:
  // 60). A loop that also polled at 50 Hz woke 300 times more.
  pid_t fast = -1;
  long at_start = -1, at_end = -1;
  std::string seen;
  Output r = run_eamos("launch " + deploy.string() + " --speed 10 --domain 46 --insecure", [&](const std::string& line) {
    seen += line;
    if (fast < 0) fast = dex_pid(seen, "Fast");
    if (line.find("Slow.Hover(60)") == std::string::npos || fast < 0) return;
    if (line.find(" start ") != std::string::npos) at_start = loop_wakeups(fast);
    if (line.find(" end ") != std::string::npos) at_end = loop_wakeups(fast);
  });
  ASSERT_EQ(r.status, 0) << r.out;
  ASSERT_GE(at_start, 0) << r.out;
  ASSERT_GE(at_end, at_start) << r.out;
  EXPECT_LT(at_end - at_start, 150) << "Fast's loop woke " << (at_end - at_start) << " times in 6 wall s of waiting";
}

TEST_F(DexResources, ADexsMemoryStaysFlatOverAThousandBarriers) {
  fs::path deploy = compile("long_loop.eamos");
  // The DEXes run "on the drones" (started here, not by the ground), so that their peak
  // resident memory comes back with their exit status.
  std::vector<pid_t> dexes;
  for (const char* drone : {"A", "B"})
    dexes.push_back(start_eamos({"dex", (deploy / drone).string(), "--speed", "200", "--domain", "47", "--insecure",
                                 "--start-timeout", "60"},
                                dir_ / (std::string(drone) + ".log")));
  for (pid_t p : dexes) ASSERT_GT(p, 0);
  Output r = run_eamos("launch " + deploy.string() + " --remote-only --speed 200 --domain 47 --insecure");
  if (r.status != 0)
    for (pid_t p : dexes) kill(p, SIGKILL);  // they would wait for a start until their timeout
  std::vector<Ended> ended;
  for (pid_t p : dexes) ended.push_back(wait_for(p));
  ASSERT_EQ(r.status, 0) << r.out;
  // 1,000 iterations: 2,000 trace events and about 1,000 triggers written by each drone.
  // A DEX whose writers kept every trigger and trace sample of the run reached 45 MB (A)
  // and 35 MB (B) here; one that keeps what late readers need stays near its start-up size.
  for (std::size_t i = 0; i < ended.size(); ++i) {
    EXPECT_EQ(ended[i].status, 0) << "DEX " << i;
    EXPECT_LT(ended[i].peak_rss_kb, 25 * 1024) << "DEX " << i << " peaked at " << ended[i].peak_rss_kb << " kB";
  }
}

}  // namespace
