// Mission files are streamed to disk, never built as a document; their MDG must be
// exactly the one `eamos graph --kind mdg` exports, and the one reader must load every
// file the writer writes. And the mission hash names the mission: the same for the same
// compiled mission, different as soon as a drone's setting or one node differs.
#include <sstream>

#include "deploy/mission_file.h"
#include "graph/export.h"
#include "helpers.h"

namespace eamos {
namespace {

using nlohmann::json;
using test::compile_mission;

/// The graph exporter's MDG nodes as a mission file holds them: without the members the
/// reader derives (docs/architecture.md, "Mission file"), `drone` only on other drones' nodes.
json file_nodes(json nodes) {
  for (json& n : nodes) {
    bool internal = n["internal"];
    for (const char* derived : {"index", "internal", "clone", "evaluated_by"}) n.erase(derived);
    if (internal) n.erase("drone");
  }
  return nodes;
}

/// The exporter's arcs as a mission file holds them: [from, to, kind] or [from, to, kind, branch].
json file_arcs(const json& arcs) {
  json out = json::array();
  for (const json& a : arcs) {
    json row = json::array({a["from"], a["to"], a["kind"]});
    if (a.contains("branch")) row.push_back(a["branch"]);
    out.push_back(row);
  }
  return out;
}

/// Compares the streamed file of every drone with the MDG the graph exporter builds, and
/// reads it back through the validating reader.
void expect_streamed_files_equal_documents(const graph::Compilation& c) {
  std::string hash = deploy::mission_hash(c);
  for (int d = 0; d < c.drone_count(); ++d) {
    std::ostringstream out;
    ASSERT_TRUE(deploy::write_drone_mission(out, c, d, hash));
    json streamed = json::parse(out.str());
    json mdg = graph::mdg_json(c, d);
    EXPECT_EQ(streamed["nodes"], file_nodes(mdg["nodes"])) << "drone " << c.drone_name(d);
    EXPECT_EQ(streamed["arcs"], file_arcs(mdg["arcs"])) << "drone " << c.drone_name(d);
    EXPECT_EQ(streamed["reads"], mdg["reads"]) << "drone " << c.drone_name(d);
    EXPECT_EQ(streamed["drone_sets"], mdg["drone_sets"]) << "drone " << c.drone_name(d);
    dex::Mission m;
    std::vector<std::string> errors;
    EXPECT_TRUE(deploy::read_mission(out.str(), c.drone_name(d), m, errors)) << errors.front();
    EXPECT_EQ(m.nodes.size(), mdg["nodes"].size());
    EXPECT_EQ(m.arcs.size(), mdg["arcs"].size());
    EXPECT_EQ(m.self, d);
    EXPECT_EQ(m.hash, hash);
  }
}

// The compiler makes every drone's file in one reused buffer: a file appended after
// another's text (left in the buffer) must be the same bytes, and carry the same file
// hash, as the file made alone, so the hash covers only its own file.
TEST(MissionFile, AFileMadeAfterAnotherInTheSameBufferIsTheFileMadeAlone) {
  auto c = compile_mission(test::listing2_text());
  ASSERT_TRUE(c);
  std::string hash = deploy::mission_hash(*c);
  std::string buffer = "text already in the buffer";
  deploy::append_drone_mission(buffer, *c, 0, hash);
  std::size_t first_end = buffer.size();
  deploy::append_drone_mission(buffer, *c, 1, hash);
  EXPECT_EQ(buffer.substr(0, 26), "text already in the buffer");
  EXPECT_EQ(buffer.substr(26, first_end - 26), deploy::mission_text(*c, 0, hash));
  std::string second = buffer.substr(first_end);
  EXPECT_EQ(second, deploy::mission_text(*c, 1, hash));
  dex::Mission m;
  std::vector<std::string> errors;
  EXPECT_TRUE(deploy::read_mission(second, c->drone_name(1), m, errors)) << (errors.empty() ? "" : errors.front());
}

TEST(MissionFile, StreamedFileEqualsDroneMissionForEveryDroneOfListing2) {
  auto c = compile_mission(test::listing2_text(), test::kListing2Fleet);
  ASSERT_TRUE(c);
  expect_streamed_files_equal_documents(*c);
}

TEST(MissionFile, StreamedFileEqualsDroneMissionForEveryDroneOfAStressMission) {
  auto c = compile_mission(test::stress_text(3000, 23));
  ASSERT_TRUE(c);
  ASSERT_EQ(c->drone_count(), 23);
  expect_streamed_files_equal_documents(*c);
}

TEST(MissionFile, StreamedFileEqualsDroneMissionForEveryControlStructure) {
  // Do*, Pause*, async, RepeatFor counts, unary operators and property arguments.
  auto c = compile_mission(test::read_text(std::string(EAMOS_SOURCE_DIR) + "/tests/deploy/missions/every_control_structure.eamos"));
  ASSERT_TRUE(c);
  expect_streamed_files_equal_documents(*c);
}

TEST(MissionHash, IsTheSameForTwoCompilesOfTheSameMission) {
  auto a = compile_mission(test::listing2_text(), test::kListing2Fleet);
  auto b = compile_mission(test::listing2_text(), test::kListing2Fleet);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(deploy::mission_hash(*a), deploy::mission_hash(*b));
  EXPECT_EQ(deploy::mission_hash(*a).size(), 64u);
}

TEST(MissionHash, ChangesWhenADronesFleetSettingChanges) {
  std::string fleet = test::kListing2Fleet;
  std::string changed = fleet;
  changed.replace(changed.find("sysid: 7"), 8, "sysid: 8");
  auto a = compile_mission(test::listing2_text(), fleet);
  auto b = compile_mission(test::listing2_text(), changed);
  ASSERT_TRUE(a && b);
  EXPECT_NE(deploy::mission_hash(*a), deploy::mission_hash(*b));
}

TEST(MissionHash, ChangesWhenOneNodeChanges) {
  std::string text = test::listing2_text();
  std::string changed = text;
  changed.replace(changed.find("Drone2.Takeoff(10)"), 18, "Drone2.Takeoff(11)");
  auto a = compile_mission(text);
  auto b = compile_mission(changed);
  ASSERT_TRUE(a && b);
  EXPECT_NE(deploy::mission_hash(*a), deploy::mission_hash(*b));
}

TEST(MissionHash, DoesNotDependOnTheSourcePath) {
  auto a = compile_mission(test::listing2_text());
  auto b = compile_mission(test::listing2_text());
  ASSERT_TRUE(a && b);
  b->source->path = "elsewhere/listing2.eamos";
  EXPECT_EQ(deploy::mission_hash(*a), deploy::mission_hash(*b));
}

}  // namespace
}  // namespace eamos

namespace eamos {
namespace {

/// Each drone's mission file as written for Listing 2 under `fleet`, read back: the text and
/// what a DEX gets from it, per drone name.
struct ReadBack {
  std::string text;
  dex::Mission mission;
};
std::map<std::string, ReadBack> read_back_each(const std::string& fleet) {
  std::map<std::string, ReadBack> out;
  auto c = test::compile_mission(test::listing2_text(), fleet);
  EXPECT_TRUE(c);
  if (!c) return out;
  std::string hash = deploy::mission_hash(*c);
  for (int d = 0; d < c->drone_count(); ++d) {
    std::ostringstream text;
    EXPECT_TRUE(deploy::write_drone_mission(text, *c, d, hash));
    ReadBack& r = out[c->drone_name(d)];
    r.text = text.str();
    std::vector<std::string> errors;
    EXPECT_TRUE(deploy::read_mission(r.text, c->drone_name(d), r.mission, errors)) << errors.front();
  }
  return out;
}

// A distributed run flies each drone from its mission file: a signing key the fleet file
// gave must come back from it, or the DEX would fly that drone unsigned.
TEST(MissionFile, ADronesSigningKeySetupAndGcsAnnouncementComeBackFromItsFileOnly) {
  std::string fleet = std::string(test::kListing2Fleet) + "";
  const std::string key = "0f1e2d3c4b5a69788796a5b4c3d2e1f000112233445566778899aabbccddeeff";
  fleet.replace(fleet.find("    failsafe: return_home\n"), 0,
               "    signing: {key: " + key + ", setup: true}\n    announce_as_gcs: true\n");
  auto files = read_back_each(fleet);
  ASSERT_EQ(files.size(), 3u);
  for (const auto& [name, r] : files) {
    bool is_drone2 = name == "Drone2";
    EXPECT_EQ(r.mission.settings.signing_key, is_drone2 ? key : "") << name;
    EXPECT_EQ(r.mission.settings.signing_setup, is_drone2) << name;
    EXPECT_EQ(r.mission.settings.announce_as_gcs, is_drone2) << name;  // its DEX announces it too
    EXPECT_EQ(r.text.find(key) != std::string::npos, is_drone2) << name;
  }
}

// A DEX judges its drone's goals by the type's tolerance: it must come back from the file.
TEST(MissionFile, ATypesGoalToleranceComesBackFromEachOfItsDronesFiles) {
  auto files = read_back_each("types:\n  DroneType2:\n    tolerance: {horizontal: 1.25, vertical: 0.75, speed: 0.5}\n" +
                              std::string(test::kListing2Fleet));
  ASSERT_EQ(files.size(), 3u);
  for (const auto& [name, r] : files) {
    const bool typed = name == "Drone2";  // `var Drone2 DroneType2`
    const fleet::GoalTolerance& t = r.mission.settings.tolerance;
    EXPECT_DOUBLE_EQ(t.horizontal_m, typed ? 1.25 : 0.5) << name;
    EXPECT_DOUBLE_EQ(t.vertical_m, typed ? 0.75 : 0.3) << name;
    EXPECT_DOUBLE_EQ(t.settled_mps, typed ? 0.5 : 0.3) << name;
  }
}

}  // namespace
}  // namespace eamos
