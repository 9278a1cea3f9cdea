// Files given on the command line are read only when they are files: a device, a file larger
// than its bound or a deployment manifest that points out of its folder is refused with a
// sentence, at once, through the real `eamos` process (none of these may hang it).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/run_eamos.h"
#include "support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using eamos_test::run_eamos;
using eamos_test::ScratchDir;

bool says(const eamos_test::Output& r, const std::string& text) { return r.out.find(text) != std::string::npos; }

TEST(InputFiles, AMissionOrFleetThatIsADeviceIsRefusedWithoutReadingIt) {
  auto mission = run_eamos("check /dev/zero");
  EXPECT_EQ(mission.status, 1) << mission.out;
  EXPECT_TRUE(says(mission, "cannot read mission file '/dev/zero': a character device, not a regular file; give "
                            "the path of the mission's .eamos file"))
      << mission.out;
  auto fleet = run_eamos("compile examples/listing2.eamos --fleet /dev/zero -o /nonexistent/out");
  EXPECT_EQ(fleet.status, 1) << fleet.out;
  EXPECT_TRUE(says(fleet, "cannot read fleet file '/dev/zero': a character device, not a regular file; check the "
                          "path given with --fleet"))
      << fleet.out;
}

// A sparse file: its size is refused before a byte of it is read.
TEST(InputFiles, AMissionLargerThan256MiBIsRefusedBeforeItIsRead) {
  ScratchDir s("input-files");
  fs::path big = s / "big.eamos";
  std::ofstream(big) << "";
  fs::resize_file(big, std::uintmax_t{300} << 20);
  auto r = run_eamos("check " + big.string());
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_TRUE(says(r, "314572800 bytes, more than the 268435456 bytes (256 MiB) it may hold")) << r.out;
}

TEST(InputFiles, AMissionPipedInIsCheckedAsItsFileIs) {
  auto r = eamos_test::run_program("cat examples/listing2.eamos | " + std::string(EAMOS_BINARY), "check /dev/stdin");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(says(r, "/dev/stdin: ok — 3 drones")) << r.out;
}

TEST(InputFiles, MonitorRefusesATraceThatIsADevice) {
  auto r = run_eamos("monitor /dev/zero --port 0");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_TRUE(says(r, "cannot read trace '/dev/zero': a character device, not a regular file")) << r.out;
}

class LaunchManifest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto r = run_eamos("compile -q --insecure examples/listing2.eamos -o " + deploy_);
    ASSERT_EQ(r.status, 0) << r.out;
  }
  eamos_test::Output launch() { return run_eamos("launch " + deploy_ + " --insecure --domain 53"); }
  ScratchDir scratch_{"launch-manifest"};
  std::string deploy_ = scratch_ / "deploy";
  std::string manifest_ = deploy_ + "/manifest.json";
};

TEST_F(LaunchManifest, AFolderOutsideTheDeploymentIsRefusedBeforeAnyDexStarts) {
  std::ifstream in(manifest_);
  nlohmann::json m = nlohmann::json::parse(in);
  m["drones"][1]["folder"] = "../../Drone2";
  std::ofstream(manifest_) << m.dump();
  auto r = launch();
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_TRUE(says(r, "manifest.json: the folder '../../Drone2' of Drone2 is not a folder inside the deployment; "
                      "compile the deployment again"))
      << r.out;
  EXPECT_FALSE(says(r, "Drone1")) << "no DEX was started: " << r.out;
}

TEST_F(LaunchManifest, AManifestThatIsADeviceIsRefused) {
  fs::remove(manifest_);
  fs::create_symlink("/dev/zero", manifest_);
  auto r = launch();
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_TRUE(says(r, "manifest.json (a character device, not a regular file); is '" + deploy_ +
                          "' a folder written by `eamos compile -o`?"))
      << r.out;
}

TEST_F(LaunchManifest, AManifestWithAWrongTypeIsRefusedAsNotAManifest) {
  std::ofstream(manifest_) << R"({"format": "eamos-deployment", "mission_hash": 5, "drones": []})";
  auto r = launch();
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_TRUE(says(r, "manifest.json is not an eamos deployment manifest; compile the deployment again")) << r.out;
}

}  // namespace
