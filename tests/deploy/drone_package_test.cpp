// write_packages adds to each drone's folder what its companion computer needs to run the
// DEX as a service (docs/deploy.md); the files it writes are the ones in config/.
#include <unistd.h>

#include <filesystem>

#include "deploy/drone_package.h"
#include "deploy/synthesize.h"
#include "helpers.h"

namespace eamos {
namespace {

namespace fs = std::filesystem;

class DronePackage : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("eamos-package-test-" + std::to_string(getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    c_ = test::compile_mission(test::listing2_text(), test::kListing2Fleet);
    ASSERT_TRUE(c_);
    Diagnostics diags;
    ASSERT_TRUE(deploy::write_deployment(*c_, dir_.string(), diags)) << diags.format();
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string file(const std::string& drone, const std::string& name) {
    return test::read_text((dir_ / drone / name).string());
  }
  fs::path dir_;
  std::unique_ptr<graph::Compilation> c_;
};

TEST_F(DronePackage, EveryDroneGetsTheUnitTheNetworkConfigurationItsEnvironmentAndNotes) {
  Diagnostics diags;
  deploy::PackageOptions o{.interface = "wlan0", .domain = 7, .ground_folder = "ground-station"};
  ASSERT_TRUE(deploy::write_packages(*c_, dir_.string(), o, diags)) << diags.format();
  std::string unit = test::read_text(std::string(EAMOS_SOURCE_DIR) + "/config/eamos-dex@.service");
  std::string network = test::read_text(std::string(EAMOS_SOURCE_DIR) + "/config/cyclonedds-network.xml");
  for (const char* drone : {"Drone1", "Drone2", "Drone3"}) {
    SCOPED_TRACE(drone);
    EXPECT_EQ(file(drone, "eamos-dex@.service"), unit);
    EXPECT_EQ(file(drone, "cyclonedds.xml"), network);
    std::string env = file(drone, "dex.env");
    EXPECT_NE(env.find("\nEAMOS_DDS_INTERFACE=wlan0\n"), std::string::npos) << env;
    EXPECT_NE(env.find("\nEAMOS_DEX_ARGS=\"--domain 7\"\n"), std::string::npos) << env;
    std::string notes = file(drone, "DEPLOY.txt");
    EXPECT_NE(notes.find("systemctl enable --now eamos-dex@" + std::string(drone)), std::string::npos) << notes;
    EXPECT_NE(notes.find("chown -R eamos:eamos /var/lib/eamos/" + std::string(drone)), std::string::npos) << notes;
  }
  // Drone2 flies a MAVLink vehicle: its notes name the connection its mission file holds.
  EXPECT_NE(file("Drone2", "DEPLOY.txt").find("adapter mavlink, connection udp://:14540"), std::string::npos);
  EXPECT_EQ(file("ground-station", "cyclonedds.xml"), network);
}

TEST_F(DronePackage, NetworkConfigurationUsesTheNamedInterfaceWithMulticastAndNoLoopback) {
  std::string xml = deploy::network_dds_config();
  EXPECT_NE(xml.find("<NetworkInterface name=\"${EAMOS_DDS_INTERFACE:?"), std::string::npos);
  EXPECT_NE(xml.find("<AllowMulticast>true</AllowMulticast>"), std::string::npos);
  EXPECT_EQ(xml.find("127.0.0.1"), std::string::npos);
  EXPECT_EQ(xml.find("<Security>"), std::string::npos) << "the DEX adds its own credentials";
}

TEST_F(DronePackage, WithoutAnInterfaceTheEnvironmentLeavesItForTheUserToSet) {
  std::string env = deploy::dex_env("Drone1", {});
  EXPECT_NE(env.find("\n#EAMOS_DDS_INTERFACE=wlan0\n"), std::string::npos) << env;
  EXPECT_EQ(env.find("\nEAMOS_DDS_INTERFACE="), std::string::npos) << env;
  EXPECT_NE(env.find("\nEAMOS_DEX_ARGS=\"--domain 0\"\n"), std::string::npos) << env;
}

TEST_F(DronePackage, InsecureMissionRunsItsDexesInsecure) {
  std::string env = deploy::dex_env("Drone1", {.insecure = true});
  EXPECT_NE(env.find("\nEAMOS_DEX_ARGS=\"--domain 0 --insecure\"\n"), std::string::npos) << env;
}

TEST_F(DronePackage, InterfaceThatIsNoInterfaceNameIsRefusedAndNothingIsWritten) {
  for (std::string bad : {"wlan0\nEAMOS_DEX_ARGS=--insecure", "a\"b", "eth 0", "averyveryverylongname", "x/y"}) {
    SCOPED_TRACE(bad);
    Diagnostics diags;
    EXPECT_FALSE(deploy::write_packages(*c_, dir_.string(), {.interface = bad}, diags));
    EXPECT_NE(diags.format().find("is not a network interface name"), std::string::npos) << diags.format();
    EXPECT_FALSE(fs::exists(dir_ / "Drone1" / "dex.env"));
  }
  for (std::string good : {"wlan0", "eth0.100", "enp3s0", "br-lan", "wlx00c0ca_a1"})
    EXPECT_TRUE(deploy::valid_interface_name(good)) << good;
}

TEST_F(DronePackage, DomainOutOfRangeIsRefused) {
  Diagnostics diags;
  EXPECT_FALSE(deploy::write_packages(*c_, dir_.string(), {.domain = 231}, diags));
  EXPECT_NE(diags.format().find("DDS domain 231 is out of range; use 0 to 230"), std::string::npos);
}

TEST_F(DronePackage, UnwritableFolderIsReportedWithThePath) {
  fs::remove_all(dir_ / "Drone3");
  std::ofstream(dir_ / "Drone3") << "a file where the folder should be";
  Diagnostics diags;
  EXPECT_FALSE(deploy::write_packages(*c_, dir_.string(), {}, diags));
  EXPECT_NE(diags.format().find("cannot write '" + (dir_ / "Drone3" / "cyclonedds.xml").string()), std::string::npos)
      << diags.format();
}

}  // namespace
}  // namespace eamos
