// write_deployment lays out DIR/manifest.json and DIR/<drone>/mission.json.
#include <unistd.h>

#include <filesystem>

#include "deploy/mission_file.h"
#include "deploy/synthesize.h"
#include "graph/pipeline.h"
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

// `eamos compile` frees the statements once the MEG is checked: the files must not change.
TEST(DeploymentCompile, FreesTheStatementsButWritesTheSameMissionFiles) {
  std::string text = test::stress_text(600, 6);
  auto full = test::compile_mission(text);
  ASSERT_TRUE(full);
  graph::Compilation lean;
  Diagnostics diags;
  ASSERT_TRUE(graph::compile(std::make_shared<SourceFile>("mission.eamos", text), fleet::Fleet{}, diags, lean, {},
                             graph::Keep::deployment_graphs))
      << diags.format();
  for (const lang::Function& f : lean.mission.functions) EXPECT_TRUE(f.body.empty()) << f.name;
  EXPECT_GT(lean.mission.expressions.size(), 0u);  // the MEG points into them
  std::string hash = deploy::mission_hash(*full);
  ASSERT_EQ(deploy::mission_hash(lean), hash);
  for (int d = 0; d < full->drone_count(); ++d)
    EXPECT_EQ(deploy::mission_text(lean, d, hash), deploy::mission_text(*full, d, hash)) << full->drone_name(d);
}

// The header's source is escaped by JsonWriter straight into the file: the file must be
// what nlohmann's dump(2) of the same header prints, byte for byte, whatever the comments
// hold (quotes, backslashes, tabs, carriage returns, control characters, DEL, UTF-8).
TEST_F(Deployment, TheTraceHeaderIsTheDumpOfTheHeaderWhateverTheSourceHolds) {
  std::string text = test::listing2_text() + "// \"quoted\" back\\slash\ttab\r\x01\x1f\x7f caf\xc3\xa9 \xf0\x9f\x9a\x81 \"source\": \"\"\n";
  auto c = test::compile_mission(text, test::kListing2Fleet);
  ASSERT_TRUE(c);
  Diagnostics diags;
  ASSERT_TRUE(deploy::write_deployment(*c, dir_.string(), diags)) << diags.format();
  std::string expected = deploy::trace_header(*c, deploy::mission_hash(*c), 0)
                             .dump(2, ' ', false, json::error_handler_t::replace) + "\n";
  EXPECT_EQ(test::read_text((dir_ / "trace-header.json").string()), expected);
}

// The AST's names are views into the source's buffer: writing the header must leave it
// the same bytes at the same address.
TEST_F(Deployment, WritingTheTraceHeaderLeavesTheSourceWhereTheNamesPointInto) {
  auto c = test::compile_mission(test::listing2_text(), test::kListing2Fleet);
  ASSERT_TRUE(c);
  const char* where = c->source->text.data();
  std::string text = c->source->text;
  Diagnostics diags;
  ASSERT_TRUE(deploy::write_deployment(*c, dir_.string(), diags)) << diags.format();
  EXPECT_EQ(c->source->text.data(), where);
  EXPECT_EQ(c->source->text, text);
  std::string header = test::read_text((dir_ / "trace-header.json").string());
  EXPECT_EQ(json::parse(header)["source"], text);
  std::string_view name = c->mission.drones.empty() ? std::string_view() : c->mission.functions.front().body.front().callee;
  EXPECT_TRUE(name.data() >= where && name.data() < where + text.size()) << "names are views into the source";
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
