// Ctrl-C, SIGTERM, a hangup and Ctrl-\ on `eamos run` while drones fly, and its output through a pipe: the
// real process, signalled the way a terminal or a service manager does. The tests wait for
// what the process prints (a takeoff succeeded), never for a time.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "support/eamos_process.h"
#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;
using eamos_test::EamosProcess;

// Two drones take off, then hover far longer than any test waits: an interrupted run is
// the only way it ends soon.
const char kHover[] = R"(package hover
var A Quad
var B Quad
func INIT() { PAR_both() }
func PAR_both() { SEQ_a(); SEQ_b() }
func SEQ_a() { A.Arm(); A.Takeoff(5); A.Hover(300); A.Land(); A.Disarm() }
func SEQ_b() { B.Arm(); B.Takeoff(5); B.Hover(300); B.Land(); B.Disarm() }
)";

class Interrupt : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eamos-interrupt-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    std::ofstream(dir_ / "hover.eamos") << kHover;
  }
  void TearDown() override {
    if (p_.pid > 0 && eamos_test::still_running(p_)) kill(p_.pid, SIGKILL);
    if (p_.out) eamos_test::wait_exit(p_);
    if (!HasFailure()) fs::remove_all(dir_);
  }
  /// Starts the hover mission at `speed` and reads until both drones are airborne.
  void start_and_wait_until_airborne(const std::string& speed) {
    p_ = eamos_test::start_eamos({"run", "-q", (dir_ / "hover.eamos").string(), "--speed", speed, "--trace",
                                  (dir_ / "trace.jsonl").string(), "--summary", (dir_ / "summary.json").string()});
    ASSERT_GT(p_.pid, 0);
    for (const char* takeoff : {"A.Takeoff(5)  succeeded", "B.Takeoff(5)  succeeded"}) {
      if (p_.seen.find(takeoff) != std::string::npos) continue;
      ASSERT_TRUE(eamos_test::read_until(p_, takeoff)) << p_.seen;
    }
  }
  /// The run ended on the stop signal `name`: exit 1, every drone landed, the report says why.
  void expect_landed_after(const std::string& name) {
    eamos_test::Exit e = eamos_test::wait_exit(p_);
    ASSERT_TRUE(e.exited) << "killed by signal " << e.status << "\n" << p_.seen;
    EXPECT_EQ(e.status, 1) << p_.seen;
    EXPECT_NE(p_.seen.find("interrupted (" + name + ")"), std::string::npos) << p_.seen;
    std::ifstream summary_file(dir_ / "summary.json");
    ASSERT_TRUE(summary_file) << p_.seen;
    nlohmann::json summary = nlohmann::json::parse(summary_file);
    EXPECT_NE(summary["error"].get<std::string>().find("interrupted (" + name + ")"), std::string::npos);
    for (const char* d : {"A", "B"}) EXPECT_TRUE(summary["drones"][d]["landed"]) << d;
  }
  fs::path dir_;
  EamosProcess p_;
};

// What `| tee log` shows: each line of the live log as it happens, not a buffer at exit,
// and what was shown stays when the process is killed. The takeoffs are read during the
// 300 s hover, which a kill ends: a buffered output would only come out at the end of the
// mission, with its landing.
TEST_F(Interrupt, PipedOutputShowsTheFlightWhileItRuns) {
  start_and_wait_until_airborne("10");
  EXPECT_TRUE(eamos_test::still_running(p_));
  ASSERT_EQ(kill(p_.pid, SIGKILL), 0);
  eamos_test::Exit e = eamos_test::wait_exit(p_);
  EXPECT_FALSE(e.exited);
  EXPECT_EQ(p_.seen.find("A.Land()"), std::string::npos) << "the takeoff was only printed at the end:\n" << p_.seen;
  EXPECT_NE(p_.seen.find("A.Hover(300)"), std::string::npos) << p_.seen;
}

TEST_F(Interrupt, CtrlCLandsEveryDroneThenReportsAndExitsNonZero) {
  start_and_wait_until_airborne("10");
  ASSERT_EQ(kill(p_.pid, SIGINT), 0);
  eamos_test::Exit e = eamos_test::wait_exit(p_);
  ASSERT_TRUE(e.exited) << "killed by signal " << e.status << "\n" << p_.seen;
  EXPECT_EQ(e.status, 1) << p_.seen;
  EXPECT_NE(p_.seen.find("interrupted (SIGINT)"), std::string::npos) << p_.seen;

  // Each airborne drone's failsafe is in the trace; nothing of the mission ran after it.
  std::map<std::string, int> failsafes;
  bool after_failsafe_start = false;
  std::ifstream in(dir_ / "trace.jsonl");
  for (std::string line; std::getline(in, line);) {
    nlohmann::json ev = nlohmann::json::parse(line);
    if (ev["event"] == "failsafe") {
      ++failsafes[ev["drone"]];
      EXPECT_EQ(ev["name"], "land");
      EXPECT_NE(ev["reason"].get<std::string>().find("interrupted (SIGINT)"), std::string::npos) << line;
    } else if (!failsafes.empty() && ev["event"] == "start") {
      after_failsafe_start = true;
    }
  }
  EXPECT_EQ(failsafes, (std::map<std::string, int>{{"A", 1}, {"B", 1}})) << p_.seen;
  EXPECT_FALSE(after_failsafe_start) << p_.seen;

  std::ifstream summary_file(dir_ / "summary.json");
  ASSERT_TRUE(summary_file) << "no summary written\n" << p_.seen;
  nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary["status"], "failed");
  EXPECT_NE(summary["error"].get<std::string>().find("interrupted (SIGINT)"), std::string::npos);
  for (const char* d : {"A", "B"}) {
    EXPECT_TRUE(summary["drones"][d]["landed"]) << d << "\n" << summary.dump(2);
    EXPECT_FALSE(summary["drones"][d]["armed"]) << d << "\n" << summary.dump(2);
  }
}

TEST_F(Interrupt, SigtermAlsoLandsEveryDrone) {
  start_and_wait_until_airborne("10");
  ASSERT_EQ(kill(p_.pid, SIGTERM), 0);
  expect_landed_after("SIGTERM");
}

// The terminal or the SSH session the run was started from closes: SIGHUP ends the flight as
// SIGTERM does, not with the default action that ended the process with drones in the air.
TEST_F(Interrupt, AHangupLandsEveryDroneAsSigtermDoes) {
  start_and_wait_until_airborne("10");
  ASSERT_EQ(kill(p_.pid, SIGHUP), 0);
  expect_landed_after("SIGHUP");
}

TEST_F(Interrupt, CtrlBackslashLandsEveryDroneAsCtrlCDoes) {
  start_and_wait_until_airborne("10");
  ASSERT_EQ(kill(p_.pid, SIGQUIT), 0);
  expect_landed_after("SIGQUIT");
}

// `nohup eamos run …`: a SIGHUP ignored when eamos started stays ignored. The SIGTERM sent
// after it is then the first signal the run takes (a SIGHUP taken would come first: it is
// the lower signal, and the report names the first).
TEST_F(Interrupt, AHangupIgnoredWhenTheRunStartedStaysIgnored) {
  struct sigaction ignore {}, before {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGHUP, &ignore, &before);  // inherited by the eamos process, as nohup does it
  start_and_wait_until_airborne("10");
  sigaction(SIGHUP, &before, nullptr);
  ASSERT_EQ(kill(p_.pid, SIGHUP), 0);
  ASSERT_EQ(kill(p_.pid, SIGTERM), 0);
  expect_landed_after("SIGTERM");
  EXPECT_EQ(p_.seen.find("SIGHUP"), std::string::npos) << p_.seen;
}

// Ctrl-Z would suspend eamos with every drone on its last command (a MAVLink vehicle flying
// on to its target, nobody watching): the commands that fly are not suspended. A stopped
// process would leave the SIGTERM pending and never end; this one lands its drones.
TEST_F(Interrupt, CtrlZDoesNotSuspendAFlight) {
  start_and_wait_until_airborne("10");
  ASSERT_EQ(kill(p_.pid, SIGTSTP), 0);
  ASSERT_EQ(kill(p_.pid, SIGTERM), 0);
  expect_landed_after("SIGTERM");
}

// `eamos run … | head`: the reader goes away mid-flight and the next line written gets
// EPIPE, not SIGPIPE's default action: the mission flies to its end and reports it.
TEST_F(Interrupt, AReaderOfTheLogThatGoesAwayDoesNotEndTheFlight) {
  fs::path summary = dir_ / "summary.json";
  auto r = eamos_test::run_program(
      "bash", "-c '" + std::string(EAMOS_BINARY) + " run examples/listing2.eamos --speed 20 --summary " +
                  summary.string() + " | head -1; echo \"eamos exited with ${PIPESTATUS[0]}\"'");
  EXPECT_NE(r.out.find("eamos exited with 0"), std::string::npos) << r.out;
  std::ifstream summary_file(summary);
  ASSERT_TRUE(summary_file) << r.out;
  EXPECT_EQ(nlohmann::json::parse(summary_file)["status"], "completed") << r.out;
}

// A signal while eamos still reads and compiles the mission (with --monitor it then draws
// the graphs, seconds on a loaded machine) is eamos' own too, not the default action that
// killed the process with status 143. The mission file is a FIFO: eamos waits for its first
// bytes, which the test writes only after the signal, so the signal comes at that known moment.
TEST_F(Interrupt, SigtermWhileTheMissionIsReadEndsTheRunBeforeAnyDroneStarts) {
  fs::path fifo = dir_ / "fifo.eamos";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  p_ = eamos_test::start_eamos({"run", "-q", fifo.string(), "--realtime", "--monitor", "127.0.0.1:0", "--summary",
                                (dir_ / "summary.json").string()});
  ASSERT_GT(p_.pid, 0);
  int fd = open(fifo.c_str(), O_WRONLY);  // returns once eamos has opened it to read
  ASSERT_GE(fd, 0);
  ASSERT_EQ(kill(p_.pid, SIGTERM), 0);
  ASSERT_EQ(write(fd, kHover, sizeof kHover - 1), static_cast<ssize_t>(sizeof kHover - 1));
  close(fd);
  eamos_test::Exit e = eamos_test::wait_exit(p_);
  ASSERT_TRUE(e.exited) << "killed by signal " << e.status << "\n" << p_.seen;
  EXPECT_EQ(e.status, 1) << p_.seen;
  EXPECT_NE(p_.seen.find("interrupted (SIGTERM) before the mission started"), std::string::npos) << p_.seen;
  EXPECT_NE(p_.seen.find("no drone was started, nothing written"), std::string::npos) << p_.seen;
  EXPECT_EQ(p_.seen.find("A.Arm()"), std::string::npos) << p_.seen;
  EXPECT_FALSE(fs::exists(dir_ / "summary.json")) << p_.seen;
}

// A second Ctrl-C is for when waiting for the failsafe is not wanted: the process ends at
// once, without the report. At speed 1 the landing from 5 m takes seconds, far longer
// than the second signal takes to arrive.
TEST_F(Interrupt, SecondCtrlCExitsAtOnce) {
  start_and_wait_until_airborne("1");
  ASSERT_EQ(kill(p_.pid, SIGINT), 0);
  ASSERT_TRUE(eamos_test::read_until(p_, "interrupt again to exit at once")) << p_.seen;
  ASSERT_EQ(kill(p_.pid, SIGINT), 0);
  eamos_test::Exit e = eamos_test::wait_exit(p_);
  ASSERT_TRUE(e.exited) << "killed by signal " << e.status << "\n" << p_.seen;
  EXPECT_EQ(e.status, 128 + SIGINT) << p_.seen;
  EXPECT_NE(p_.seen.find("exiting now"), std::string::npos) << p_.seen;
  EXPECT_FALSE(fs::exists(dir_ / "summary.json")) << "it waited for the landing\n" << p_.seen;
}

}  // namespace
