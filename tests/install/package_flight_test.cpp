// A packaged deployment flown the way its drones run it: each DEX started with its own
// dex.env (read as the unit reads it) and its folder's cyclonedds.xml on a real network
// interface (multicast, DDS Security on), the ground with `launch --remote-only` and the
// ground's configuration. Real time (speed 10): label realtime.
#include <regex>

#include "install/shell.h"

namespace eamos {
namespace {

namespace fs = std::filesystem;
using eamos_test::sh;
using eamos_test::shell_quote;

class PackagedFleet : public eamos_test::TempDir {};

TEST_F(PackagedFleet, FliesOverTheNetworkInterfaceWithTheFilesOfItsPackage) {
  std::string interface = eamos_test::network_interface();
  if (interface.empty()) GTEST_SKIP() << "no network interface up with multicast and IPv4 besides loopback";
  std::string eamos = shell_quote(EAMOS_BINARY);
  eamos_test::Shell compiled =
      sh(eamos + " compile -q " + shell_quote(std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos") +
         " --fleet " + shell_quote(std::string(EAMOS_SOURCE_DIR) + "/examples/listing2-right.yaml") + " -o " +
         shell_quote((dir_ / "deploy").string()) + " --package --interface " + interface + " --domain 227");
  ASSERT_EQ(compiled.status, 0) << compiled.out;
  // Each DEX in the background with its dex.env, the ground in front; `wait` returns when
  // every DEX has exited (after the mission, or on the ground's ABORT if the barrier fails).
  std::string script = "cd " + shell_quote(dir_.string()) + "\n" +
                       "for d in Drone1 Drone2 Drone3; do\n"
                       "  (set -a; . deploy/$d/dex.env; set +a\n"
                       "   exec " + eamos + " dex deploy/$d --dds-config deploy/$d/cyclonedds.xml $EAMOS_DEX_ARGS"
                       " --speed 10 --start-timeout 60 > $d.log 2>&1) &\n"
                       "done\n"
                       "EAMOS_DDS_INTERFACE=" + interface + " " + eamos +
                       " launch deploy --remote-only --domain 227 --speed 10"
                       " --dds-config deploy/ground-station/cyclonedds.xml --summary summary.json\n"
                       "rc=$?; wait; exit $rc\n";
  eamos_test::Shell flight = sh("bash -c " + shell_quote(script));
  EXPECT_EQ(flight.status, 0) << flight.out;
  EXPECT_TRUE(std::regex_search(flight.out, std::regex("\nmission completed in [0-9.]+ s"))) << flight.out;
  for (const char* drone : {"Drone1", "Drone2", "Drone3"}) {
    std::string log = eamos_test::read_file(dir_ / (std::string(drone) + ".log"));
    EXPECT_NE(log.find(std::string(drone) + ": mission completed\n"), std::string::npos) << log;
  }
  EXPECT_NE(eamos_test::read_file(dir_ / "summary.json").find("\"status\": \"completed\""), std::string::npos);
}

}  // namespace
}  // namespace eamos
