// write_deployment lays out DIR/manifest.json and DIR/<drone>/mission.json.
#include <unistd.h>

#include <filesystem>

#include "deploy/synthesize.h"
#include "helpers.h"

namespace eamos {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// A fresh folder per test, removed afterwards.
class Deployment : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("eamos-deploy-test-" + std::to_string(getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(Deployment, WritesAManifestAndOneMissionFilePerDrone) {
  auto c = test::compile_mission(test::listing2_text(), test::kListing2Fleet);
  ASSERT_TRUE(c);
  Diagnostics diags;
  ASSERT_TRUE(deploy::write_deployment(*c, dir_.string(), diags)) << diags.format();

  json manifest = json::parse(test::read_text((dir_ / "manifest.json").string()));
  EXPECT_EQ(manifest["format"], "eamos-deployment");
  EXPECT_EQ(manifest["format_version"], deploy::kMissionFormatVersion);
  EXPECT_EQ(manifest["mission_hash"], deploy::mission_hash(*c));
  ASSERT_EQ(manifest["drones"].size(), 3u);

  for (int d = 0; d < c->drone_count(); ++d) {
    fs::path file = dir_ / c->drone_name(d) / "mission.json";
    ASSERT_TRUE(fs::exists(file)) << file;
    EXPECT_EQ(manifest["drones"][d]["mission"], c->drone_name(d) + "/mission.json");
    json mission = json::parse(test::read_text(file.string()));
    EXPECT_EQ(mission["format"], "eamos-mission");
    EXPECT_EQ(mission["format_version"], deploy::kMissionFormatVersion);
    EXPECT_EQ(mission["mission_hash"], manifest["mission_hash"]);
    EXPECT_EQ(mission["drone"]["name"], c->drone_name(d));
    EXPECT_EQ(test::read_text(file.string()), deploy::mission_text(*c, d, deploy::mission_hash(*c)) + "\n");
  }
}

TEST_F(Deployment, ReportsAnOutputFolderThatCannotBeCreated) {
  auto c = test::compile_mission(test::listing2_text());
  ASSERT_TRUE(c);
  // A regular file where the folder should go.
  { std::ofstream(dir_.string()) << "not a folder"; }
  Diagnostics diags;
  EXPECT_FALSE(deploy::write_deployment(*c, (dir_ / "deploy").string(), diags));
  EXPECT_TRUE(diags.has_errors());
}

}  // namespace
}  // namespace eamos
