// `eamos compile --package`: each drone's folder holds a systemd unit that systemd itself
// accepts, and a DDS configuration on which the real `eamos dex` joins the network.
#include "install/shell.h"

namespace eamos {
namespace {

namespace fs = std::filesystem;
using eamos_test::shell_quote;
using eamos_test::sh;

class CompilePackage : public eamos_test::TempDir {
 protected:
  eamos_test::Shell compile(const std::string& options) {
    return sh(shell_quote(EAMOS_BINARY) + " compile -q " + shell_quote(std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos") +
              " -o " + shell_quote((dir_ / "deploy").string()) + " " + options);
  }
  /// `systemd-analyze verify` of Drone1's unit as instance `eamos-dex@Drone1.service`. Its
  /// man page (Documentation=) is not looked up: it is installed with eamos (Install.*).
  eamos_test::Shell verify(const fs::path& unit_dir) {
    return sh("systemd-analyze verify --man=no " + shell_quote((unit_dir / "eamos-dex@Drone1.service").string()));
  }
};

TEST_F(CompilePackage, UnitPassesSystemdAnalyzeVerify) {
  if (sh("command -v systemd-analyze").status != 0) GTEST_SKIP() << "systemd-analyze not installed (Debian: systemd)";
  eamos_test::Shell r = compile("--package --interface wlan0");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("packaged each drone's DEX as a systemd service"), std::string::npos) << r.out;
  eamos_test::Shell v = verify(dir_ / "deploy/Drone1");
  EXPECT_EQ(v.status, 0) << v.out;
  EXPECT_EQ(v.out, "") << "systemd-analyze warns about the unit";
  // The check can fail: a unit with a key systemd does not know, or a bad value, is reported.
  fs::create_directories(dir_ / "broken");
  std::string unit = eamos_test::read_file(dir_ / "deploy/Drone1/eamos-dex@.service");
  unit.replace(unit.find("Restart=always"), 14, "Restart=sometimes");
  std::ofstream(dir_ / "broken/eamos-dex@.service") << unit;
  eamos_test::Shell broken = verify(dir_ / "broken");
  EXPECT_NE(broken.out.find("Failed to parse service restart specifier, ignoring: sometimes"), std::string::npos)
      << broken.out;
}

TEST_F(CompilePackage, DexJoinsDdsOnTheInterfaceItsEnvironmentNamesAndRefusesWithoutOne) {
  std::string interface = eamos_test::network_interface();
  if (interface.empty()) GTEST_SKIP() << "no network interface up with multicast and IPv4 besides loopback";
  ASSERT_EQ(compile("--package --domain 229").status, 0);
  fs::path drone = dir_ / "deploy/Drone1";
  std::string dex = shell_quote(EAMOS_BINARY) + " dex " + shell_quote(drone.string()) + " --dds-config " +
                    shell_quote((drone / "cyclonedds.xml").string()) + " --domain 229 --start-timeout 0.5";
  // With its credentials (DDS Security on) on the named interface it waits for its peers;
  // no ground runs, so no start comes.
  eamos_test::Shell joined = sh("EAMOS_DDS_INTERFACE=" + interface + " " + dex);
  EXPECT_EQ(joined.status, 1);
  EXPECT_NE(joined.out.find("Drone1: DEX of mission"), std::string::npos) << joined.out;
  EXPECT_NE(joined.out.find("no start within 0.5 s"), std::string::npos) << joined.out;
  eamos_test::Shell unset = sh("unset EAMOS_DDS_INTERFACE; " + dex);
  EXPECT_EQ(unset.status, 1);
  EXPECT_NE(unset.out.find("EAMOS_DDS_INTERFACE: is not set: name the network interface DDS uses in dex.env"),
            std::string::npos)
      << unset.out;
  EXPECT_NE(unset.out.find("cannot create DDS domain 229"), std::string::npos) << unset.out;
}

TEST_F(CompilePackage, BadInterfaceIsRefusedBeforeAnythingIsWritten) {
  eamos_test::Shell r = compile("--package --interface 'wlan0 --insecure'");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("eamos: error: --interface 'wlan0 --insecure' is not a network interface name"),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(fs::exists(dir_ / "deploy"));
  eamos_test::Shell alone = compile("--interface wlan0");
  EXPECT_EQ(alone.status, 1);
  EXPECT_NE(alone.out.find("eamos: error: --interface needs --package too"), std::string::npos) << alone.out;
  EXPECT_FALSE(fs::exists(dir_ / "deploy"));
}

}  // namespace
}  // namespace eamos
