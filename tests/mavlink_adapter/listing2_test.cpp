// Listing 2 flown by `eamos run` against three `eamos sim-vehicle` processes over loopback
// UDP gives every drone the same sequence of actions and outcomes as the built-in simulator.
//
// Compared per drone: action starts and ends with their outcomes. Not compared: times,
// condition evaluations, and how often Drone2's picture loop runs. Those depend on which of
// two independent drones gets somewhere first, and a vehicle reached over MAVLink arrives a
// few tenths of a second later than the kinematic simulator (PX4 wants half a second of
// setpoints before OFFBOARD, telemetry comes at 10 Hz, a goal counts only once the vehicle
// has settled). So repeated TakePicture pairs count as one.
#include <gtest/gtest.h>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>

#include <nlohmann/json.hpp>

#include "trace/trace_schema.h"

#include "support/run_eamos.h"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using Sequences = std::map<std::string, std::vector<std::string>>;

int run(const std::string& args, std::string& output) {
  eamos_test::Output r = eamos_test::run_eamos(args);
  output += r.out;
  return r.status;
}

/// `north`: where it stands, metres north of the others' reference point; the fleet files
/// here put drone i's home at 5·(i-1) m north (the default), so the vehicles stand there.
pid_t spawn_vehicle(int port, int sysid, const char* duration = "400", const char* battery = "100",
                    double north = -1) {
  if (north < 0) north = 5.0 * (sysid - 1);
  std::vector<std::string> args = {EAMOS_BINARY, "sim-vehicle", "--udp", std::to_string(port),
                                   "--sysid", std::to_string(sysid), "--speed", "4",
                                   "--duration", duration, "--battery", battery, "--north", std::to_string(north)};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  posix_spawn(&pid, EAMOS_BINARY, nullptr, nullptr, argv.data(), environ);
  return pid;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// What breaks the trace schema (docs/trace.md), one line per fault; "" when nothing does.
std::string schema_errors(const fs::path& trace) {
  std::ifstream in(trace);
  std::string all;
  for (const std::string& e : eamos::trace::check_trace(in, {.strict = true})) all += e + "\n";
  return all;
}

/// A telemetry sample with the autopilot's own mode and a heading from GLOBAL_POSITION_INT.
bool has_mavlink_telemetry(const fs::path& trace) {
  std::ifstream in(trace);
  for (std::string line; std::getline(in, line);) {
    auto e = nlohmann::json::parse(line);
    if (e.value("event", "") == "telemetry" && e.value("mode", "") == "OFFBOARD" && e["heading"].is_number())
      return true;
  }
  return false;
}

Sequences actions(const fs::path& trace) {
  Sequences out;
  std::ifstream in(trace);
  std::string line;
  while (std::getline(in, line)) {
    auto e = nlohmann::json::parse(line);
    std::string kind = e.value("event", "");
    if (kind != "start" && kind != "end") continue;
    std::string item = kind + " " + e.value("name", "");
    if (kind == "end") item += " " + e.value("outcome", "");
    auto& seq = out[e.value("drone", "")];
    // A repeated picture (start, end) is the same step of the loop.
    if (item == "end TakePicture succeeded" && seq.size() >= 3 &&
        seq[seq.size() - 1] == "start TakePicture" && seq[seq.size() - 2] == item) {
      seq.pop_back();
      continue;
    }
    seq.push_back(item);
  }
  return out;
}

TEST(MavlinkListing2, ThreeSimVehiclesFlyTheSameActionsAsTheSimulator) {
  fs::path dir = fs::temp_directory_path() / ("eamos-mavlink-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string mission = std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos";
  std::string out;
  ASSERT_EQ(run("run " + mission + " --fleet " + EAMOS_SOURCE_DIR + "/examples/listing2-right.yaml --trace " +
                    (dir / "sim.jsonl").string(), out), 0) << out;

  std::vector<pid_t> vehicles;
  for (int i = 1; i <= 3; ++i) vehicles.push_back(spawn_vehicle(25320 + i, i));
  out.clear();
  int status = run("run " + mission + " --fleet " + EAMOS_TEST_DATA + "/data/listing2-mavlink.yaml" +
                   " --speed 4 --time-limit 120 --trace " + (dir / "mavlink.jsonl").string(), out);
  for (pid_t pid : vehicles) {
    kill(pid, SIGTERM);
    waitpid(pid, nullptr, 0);
  }
  ASSERT_EQ(status, 0) << out;

  EXPECT_EQ(schema_errors(dir / "mavlink.jsonl"), "");
  EXPECT_TRUE(has_mavlink_telemetry(dir / "mavlink.jsonl"));
  Sequences sim = actions(dir / "sim.jsonl");
  Sequences mav = actions(dir / "mavlink.jsonl");
  ASSERT_EQ(sim.size(), 3u);
  for (const auto& [drone, seq] : sim) EXPECT_EQ(mav[drone], seq) << drone;
  fs::remove_all(dir);
}

TEST(MavlinkListing2, OneDexProcessPerDroneEachFlyingItsOwnVehicle) {
  // The paper's deployment: every drone's DEX runs on its own computer beside its autopilot;
  // here as processes over Cyclone DDS (domain 77, used by no other test), each DEX with a
  // mavlink drone talking to its own sim-vehicle.
  fs::path dir = fs::temp_directory_path() / ("eamos-mavlink-dist-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string mission = std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos";
  std::string out;
  ASSERT_EQ(run("run " + mission + " --fleet " + EAMOS_SOURCE_DIR + "/examples/listing2-right.yaml --trace " +
                    (dir / "sim.jsonl").string(), out), 0) << out;
  // The same fleet on ports of its own (ctest may run the in-process test at the same time).
  std::string fleet = read_text(fs::path(EAMOS_TEST_DATA) / "data/listing2-mavlink.yaml");
  for (size_t at; (at = fleet.find(":2532")) != std::string::npos;) fleet.replace(at, 5, ":2535");
  std::ofstream(dir / "fleet.yaml") << fleet;
  std::vector<pid_t> vehicles;
  for (int i = 1; i <= 3; ++i) vehicles.push_back(spawn_vehicle(25350 + i, i));
  out.clear();
  int status = run("run " + mission + " --fleet " + (dir / "fleet.yaml").string() +
                   " --distributed --domain 77 --speed 4 --time-limit 120 --deploy-dir " +
                   (dir / "deploy").string() + " --trace " + (dir / "mavlink.jsonl").string(), out);
  for (pid_t pid : vehicles) {
    kill(pid, SIGTERM);
    waitpid(pid, nullptr, 0);
  }
  ASSERT_EQ(status, 0) << out;
  EXPECT_EQ(schema_errors(dir / "mavlink.jsonl"), "");
  EXPECT_TRUE(has_mavlink_telemetry(dir / "mavlink.jsonl"));
  Sequences sim = actions(dir / "sim.jsonl");
  Sequences mav = actions(dir / "mavlink.jsonl");
  for (const auto& [drone, seq] : sim) EXPECT_EQ(mav[drone], seq) << drone;
  fs::remove_all(dir);
}

TEST(MavlinkRun, ARefusalFailsTheMissionWithTheAutopilotsReasonAndTheRunEnds) {
  pid_t vehicle = spawn_vehicle(25405, 1, "120", "0");  // an empty battery: arming is refused
  std::string out;
  const std::string data = EAMOS_TEST_DATA;
  auto started = std::chrono::steady_clock::now();
  int status = run("run " + data + "/data/arm-refused.eamos --fleet " + data +
                   "/data/arm-refused.yaml --speed 4", out);
  double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  kill(vehicle, SIGTERM);
  waitpid(vehicle, nullptr, 0);
  EXPECT_EQ(status, 1) << out;
  EXPECT_NE(out.find("mission failed: Drone1.Arm (line 4) failed: refused by PX4: "
                     "MAV_CMD_COMPONENT_ARM_DISARM: MAV_RESULT_DENIED"),
            std::string::npos)
      << out;
  EXPECT_LT(wall, 15.0);  // not the time limit: a failed run ends once the drones are down
}

// One DEX per drone: Drone2's Arm is refused, and Drone1, armed on the ground, runs its
// failsafe. Its DEX stays until the vehicle is disarmed, not only down: the summary shows
// every drone disarmed (a DEX that ended at "landed" left it armed, seen on PX4 SITL).
TEST(MavlinkRun, ADistributedRefusalEndsWithEveryDroneDisarmed) {
  fs::path dir = fs::temp_directory_path() / ("eamos-mavlink-refused-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  pid_t armed = spawn_vehicle(25381, 1, "120");
  pid_t refusing = spawn_vehicle(25382, 2, "120", "0");  // an empty battery: arming is refused
  std::string out;
  const std::string data = EAMOS_TEST_DATA;
  int status = run("run " + data + "/data/arm-refused-pair.eamos --fleet " + data +
                       "/data/arm-refused-pair.yaml --distributed --domain 79 --speed 4 --time-limit 60 --deploy-dir " +
                       (dir / "deploy").string() + " --summary " + (dir / "summary.json").string(),
                   out);
  for (pid_t pid : {armed, refusing}) {
    kill(pid, SIGTERM);
    waitpid(pid, nullptr, 0);
  }
  EXPECT_EQ(status, 1) << out;
  auto summary = nlohmann::json::parse(read_text(dir / "summary.json"), nullptr, false);
  ASSERT_FALSE(summary.is_discarded()) << out;
  EXPECT_NE(summary.value("error", "").find("Drone2.Arm (line 6) failed: refused by PX4"), std::string::npos)
      << summary.dump(2);
  for (const char* d : {"Drone1", "Drone2"}) {
    EXPECT_EQ(summary["drones"][d].value("armed", true), false) << d << "\n" << summary.dump(2) << "\n" << out;
    EXPECT_EQ(summary["drones"][d].value("landed", false), true) << d << "\n" << summary.dump(2);
  }
  fs::remove_all(dir);
}

// Three vehicles standing on one spot while the fleet file puts their homes 5 m apart (the
// default homes, 0, 5 and 10 m north): every drone's mission frame would be shifted, routes
// meant to be apart would cross. The run is refused before anything arms, naming where
// each misplaced vehicle stands and where its home says.
void expect_homes_refused(const std::string& out, const fs::path& trace) {
  EXPECT_NE(out.find("the vehicles do not stand where the fleet file puts them; nothing was armed"), std::string::npos)
      << out;
  EXPECT_NE(out.find("Drone2 stands at [0.0, 0.0] in the mission frame"), std::string::npos) << out;
  EXPECT_NE(out.find("its home in the fleet file is [0.0, 5.0]: 5.0 m apart, more than home_tolerance 3 m"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("Drone3 stands at [0.0, 0.0]"), std::string::npos) << out;
  EXPECT_NE(out.find("its home in the fleet file is [0.0, 10.0]: 10.0 m apart"), std::string::npos) << out;
  EXPECT_EQ(out.find("Drone1 stands"), std::string::npos) << out;  // the one the others are measured from
  // The trace holds its header and the mission's failure, nothing that ran.
  std::ifstream in(trace);
  for (std::string line; std::getline(in, line);) {
    std::string event = nlohmann::json::parse(line).value("event", "");
    EXPECT_TRUE(event == "header" || event == "mission") << "something ran: " << line;
  }
}

/// Flies Listing 2 on three sim-vehicles standing on one spot (ports 25`tens`1..3, fleet
/// ports rewritten to match) with `extra` options (`dir` is its folder), and expects the homes refused.
void fly_on_one_spot(const std::string& name, const std::string& tens,
                     const std::function<std::string(const fs::path& dir)>& extra) {
  fs::path dir = fs::temp_directory_path() / ("eamos-mavlink-" + name + "-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string fleet = read_text(fs::path(EAMOS_TEST_DATA) / "data/listing2-mavlink.yaml");
  for (size_t at; (at = fleet.find(":2532")) != std::string::npos;) fleet.replace(at, 5, ":25" + tens);
  std::ofstream(dir / "fleet.yaml") << fleet;
  std::vector<pid_t> vehicles;
  for (int i = 1; i <= 3; ++i) vehicles.push_back(spawn_vehicle(std::stoi("25" + tens + "0") + i, i, "60", "100", 0.0));
  std::string out;
  int status = run("run " + std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos --fleet " +
                       (dir / "fleet.yaml").string() + extra(dir) + " --speed 4 --trace " + (dir / "trace.jsonl").string(),
                   out);
  for (pid_t pid : vehicles) {
    kill(pid, SIGTERM);
    waitpid(pid, nullptr, 0);
  }
  EXPECT_EQ(status, 1) << out;
  expect_homes_refused(out, dir / "trace.jsonl");
  fs::remove_all(dir);
}

TEST(MavlinkHomes, VehiclesOnOneSpotWhileTheFleetPutsThemApartAreRefusedBeforeArming) {
  fly_on_one_spot("homes", "42", [](const fs::path&) { return std::string(); });
}

// The same field with one DEX per drone (domain 78, used by no other test): each DEX reports
// where its vehicle stands with its READY, and the ground refuses the start barrier.
TEST(MavlinkHomes, OneDexPerDroneTheGroundRefusesTheStartWhenTheVehiclesStandElsewhere) {
  fly_on_one_spot("homes-dist", "43", [](const fs::path& dir) {
    return " --distributed --domain 78 --deploy-dir " + (dir / "deploy").string();
  });
}

}  // namespace
