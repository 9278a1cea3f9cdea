// Every failure the mavlink adapter produces reaches the trace and the summary of `eamos run`
// with its uniform kind (FailureReason) and the autopilot's own words as detail, flown
// against `eamos sim-vehicle` processes over loopback UDP. Each test has its own port.
#include <gtest/gtest.h>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <functional>
#include <regex>
#include <thread>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mavlink/enums.h"
#include "mavlink/frame.h"
#include "mavlink/link.h"
#include "mavlink/payloads.h"
#include "fleet/link_url.h"
#include "support/eamos_process.h"

extern char** environ;

namespace {

namespace fs = std::filesystem;
const std::string kData = std::string(EAMOS_TEST_DATA) + "/data/";

struct Vehicle {
  pid_t pid = -1;
  Vehicle(int port, const char* duration, const char* battery = "100") {
    std::vector<std::string> args = {EAMOS_BINARY, "sim-vehicle", "--udp", std::to_string(port), "--sysid", "1",
                                     "--speed", "4", "--duration", duration, "--battery", battery};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn(&pid, EAMOS_BINARY, nullptr, nullptr, argv.data(), environ);
  }
  ~Vehicle() {
    if (pid <= 0) return;
    kill(pid, SIGTERM);
    waitpid(pid, nullptr, 0);
  }
};

struct FlightRun {
  fs::path dir;
  std::string out;
  int status = -1;
  nlohmann::json end;      ///< the trace's `end` event with outcome "failed"
  nlohmann::json summary;  ///< the summary's "failure"
};

/// `eamos run long-flight.eamos` against the vehicle on `port`; `extra` goes into the
/// drone's fleet entry; `while_flying` runs once the FlyTo has started, `when_done` once the
/// output shows `done_when` (before the run ends).
FlightRun fly(const std::string& mission, int port, const std::string& extra,
        const std::function<void()>& while_flying = {}, const std::string& done_when = "",
        const std::function<void()>& when_done = {}) {
  FlightRun r;
  r.dir = fs::temp_directory_path() /
          ("eamos-mav-failure-" + std::to_string(::getpid()) + "-" + std::to_string(port));
  fs::create_directories(r.dir);
  std::ofstream(r.dir / "fleet.yaml") << "drones:\n  Drone1: {adapter: mavlink, connection: \"udp://127.0.0.1:"
                                      << port << "\", sysid: 1" << extra << "}\n";
  eamos_test::EamosProcess p = eamos_test::start_eamos(
      {"run", kData + mission, "--fleet", (r.dir / "fleet.yaml").string(), "--speed", "4", "--time-limit", "120",
       "--trace", (r.dir / "trace.jsonl").string(), "--summary", (r.dir / "summary.json").string()});
  if (while_flying && eamos_test::read_until(p, "Drone1.FlyTo(")) {
    while_flying();
    eamos_test::read_until(p, done_when);
    if (when_done) when_done();
  }
  eamos_test::Exit e = eamos_test::wait_exit(p);
  r.out = p.seen;
  r.status = e.exited ? e.status : -1;
  std::ifstream trace(r.dir / "trace.jsonl");
  for (std::string line; std::getline(trace, line);) {
    auto j = nlohmann::json::parse(line);
    if (j.value("event", "") == "end" && j.value("outcome", "") == "failed") r.end = j;
  }
  std::ifstream summary(r.dir / "summary.json");
  if (summary) r.summary = nlohmann::json::parse(summary)["failure"];
  fs::remove_all(r.dir);
  return r;
}

TEST(MavlinkFailureReasons, TheAutopilotsRefusalIsRefusedWithItsMavResultAsDetail) {
  Vehicle v(25401, "120", "0");  // an empty battery: PX4 refuses to arm
  FlightRun r = fly("arm-refused.eamos", 25401, "");
  EXPECT_EQ(r.status, 1) << r.out;
  ASSERT_TRUE(r.end.is_object()) << r.out;
  EXPECT_EQ(r.end["name"], "Arm");
  EXPECT_EQ(r.end["failure"], "refused");
  EXPECT_EQ(r.end["detail"], "MAV_CMD_COMPONENT_ARM_DISARM: MAV_RESULT_DENIED (denied by the autopilot)");
  EXPECT_EQ(r.summary["kind"], "refused");
  EXPECT_EQ(r.summary["detail"], r.end["detail"]);
}

TEST(MavlinkFailureReasons, AFlightPastItsDeadlineIsTimedOut) {
  Vehicle v(25402, "200");
  FlightRun r = fly("long-flight.eamos", 25402, ", timeouts: {FlyTo: 2}");
  EXPECT_EQ(r.status, 1) << r.out;
  ASSERT_TRUE(r.end.is_object()) << r.out;
  EXPECT_EQ(r.end["name"], "FlyTo");
  EXPECT_EQ(r.end["failure"], "timed_out");
  // The sim-vehicle's clock may run a little slow on a loaded machine (it runs at nice 19 in
  // the suite): the deadline then stretches, and the detail still names the fleet's 2.0 s.
  const std::string detail = r.end["detail"].is_string() ? r.end["detail"].get<std::string>() : "";
  EXPECT_TRUE(detail == "deadline 2.0 s after start" ||
              std::regex_match(detail, std::regex(R"(deadline 2\.0 s of the vehicle's clock after start \(2\.\d s of )"
                                                  R"(mission time: the vehicle's clock ran at 0\.\d\d of it\))")))
      << detail;
  EXPECT_EQ(r.summary["kind"], "timed_out");
}

TEST(MavlinkFailureReasons, AVehicleThatFallsSilentIsLinkLost) {
  // The vehicle process ends by itself 8 mission seconds in, while the drone waits armed on
  // the ground (in the air the run would wait for a landing it cannot see; a running action
  // failing on link loss is flight_test's LinkLossFailsTheRunningAction).
  Vehicle v(25403, "8");
  FlightRun r = fly("arm-and-wait.eamos", 25403, "");
  EXPECT_EQ(r.status, 1) << r.out;
  ASSERT_TRUE(r.end.is_object()) << r.out;
  EXPECT_EQ(r.end["name"], "Takeoff");
  EXPECT_EQ(r.end["failure"], "link_lost");
  EXPECT_EQ(r.summary["kind"], "link_lost");
  EXPECT_NE(r.end.value("reason", "").find("link lost: no HEARTBEAT from system 1"), std::string::npos) << r.end;
}

TEST(MavlinkFailureReasons, APilotsModeSwitchIsPilotTookOverWithTheModeAsDetail) {
  // The vehicle says where it receives: a second ground station there plays the pilot.
  eamos_test::EamosProcess vehicle = eamos_test::start_eamos(
      {"sim-vehicle", "--udp", "25404", "--sysid", "1", "--speed", "4", "--duration", "200"});
  ASSERT_TRUE(eamos_test::read_until(vehicle, "receiving on port ")) << vehicle.seen;
  int vehicle_port = std::stoi(vehicle.seen.substr(vehicle.seen.find("receiving on port ") + 18));
  std::atomic<bool> switched{false};
  std::thread pilot;
  FlightRun r = fly("long-flight.eamos", 25404, "", [&] {
    // Switches to POSCTL, as a pilot's switch would, until the flight failed for it: one
    // switch that arrives before the adapter's own OFFBOARD request would be undone by it.
    pilot = std::thread([&switched, vehicle_port] {
      auto gcs = eamos::mavlink::Link::open(
          *eamos::fleet::parse_link_url("udpout://127.0.0.1:" + std::to_string(vehicle_port)).endpoint,
          [](eamos::mavlink::Frame) {});
      if (!gcs.link) return;
      eamos::mavlink::CommandLong c;
      c.target_system = 1;
      c.target_component = 1;
      c.command = eamos::mavlink::cmd::DO_SET_MODE;
      c.param = {1, eamos::mavlink::px4::MAIN_POSCTL, 0};
      eamos::mavlink::Encoder gcs_encoder{255, 190, 0};
      while (!switched) {
        gcs.link->send(gcs_encoder.encode(eamos::mavlink::pack(c)));
        usleep(250 * 1000);
      }
    });
  }, "failed [", [&] {
    switched = true;  // the failsafe's landing must not be switched away too
    if (pilot.joinable()) pilot.join();
  });
  kill(vehicle.pid, SIGTERM);
  eamos_test::wait_exit(vehicle);
  EXPECT_EQ(r.status, 1) << r.out;
  ASSERT_TRUE(r.end.is_object()) << r.out;
  EXPECT_EQ(r.end["name"], "FlyTo");
  EXPECT_EQ(r.end["failure"], "pilot_took_over");
  EXPECT_EQ(r.end["reason"], "the vehicle left OFFBOARD for POSCTL");
  EXPECT_EQ(r.end["detail"], "mode POSCTL");
  EXPECT_EQ(r.summary["kind"], "pilot_took_over");
}

}  // namespace
