// The mission reader trusts nothing in a mission file: every defect is reported as
// "FILE: error: WHERE: WHAT" (WHERE a JSON pointer), all of them at once, and no file makes
// it crash. Each test damages a file the writer wrote in one way; most recompute the file
// hash afterwards so that the reader's own checks, not the hash, must find the defect.
#include <sstream>

#include <nlohmann/json.hpp>

#include "deploy/mission_file.h"
#include "helpers.h"
#include "support/mission_edit.h"

namespace eamos {
namespace {

using eamos_test::replace_once;
using eamos_test::reseal;
using nlohmann::json;

class MissionReader : public ::testing::Test {
 protected:
  void SetUp() override {
    c_ = test::compile_mission(test::listing2_text(), test::kListing2Fleet);
    ASSERT_TRUE(c_);
    text_ = deploy::mission_text(*c_, 0, deploy::mission_hash(*c_));
    doc_ = json::parse(text_);
  }

  /// Every defect the reader reports for `text`, one per line; "" when it accepts it.
  std::string defects(const std::string& text) {
    dex::Mission m;
    std::vector<std::string> errors;
    bool ok = deploy::read_mission(text, "Drone1/mission.json", m, errors);
    EXPECT_EQ(ok, errors.empty());
    std::string out;
    for (const auto& e : errors) out += e + "\n";
    return out;
  }

  /// The exact text of arc `i` as written, on a line of its own: `[F,T,`.
  std::string arc_start(std::size_t i) {
    const json& a = doc_["arcs"][i];
    return "\n  [" + a[0].dump() + "," + a[1].dump() + ",";
  }

  std::unique_ptr<graph::Compilation> c_;
  std::string text_;
  json doc_;
};

TEST_F(MissionReader, AcceptsTheFileTheWriterWrote) {
  EXPECT_EQ(defects(text_), "");
  EXPECT_EQ(defects(text_ + "\n"), "");  // as it lies on disk, with its final line break
}

TEST_F(MissionReader, RefusesAFileEditedAfterCompileWhoseHashNoLongerMatches) {
  std::string edited = replace_once(text_, "\"battery\":87.5", "\"battery\":50.0");
  EXPECT_EQ(defects(edited),
            "Drone1/mission.json: error: /file_hash: the file's content does not match its hash; it was edited or "
            "damaged after `eamos compile` (compile the mission again)\n");
}

TEST_F(MissionReader, RefusesAFileWithoutItsFileHash) {
  std::size_t at = text_.rfind(",\n \"file_hash\"");
  ASSERT_NE(at, std::string::npos);
  std::string cut = text_.substr(0, at) + "\n}";
  EXPECT_NE(defects(cut).find("Drone1/mission.json: error: the file does not end with its \"file_hash\""),
            std::string::npos);
}

TEST_F(MissionReader, RefusesAnArcToANodeThatIsNotInTheFile) {
  std::size_t nodes = doc_["nodes"].size();
  std::string from = doc_["arcs"][0][0].dump();
  std::string edited = reseal(replace_once(text_, arc_start(0), "\n  [" + from + ",9999,"));
  EXPECT_EQ(defects(edited), "Drone1/mission.json: error: /arcs/0/1: 9999 is out of range (0 to " +
                                 std::to_string(nodes - 1) + ")\n");
}

TEST_F(MissionReader, RefusesANegativeNodeIndex) {
  std::string to = doc_["arcs"][1][1].dump();
  std::string edited = reseal(replace_once(text_, arc_start(1), "\n  [-1," + to + ","));
  EXPECT_NE(defects(edited).find("error: /arcs/1/0: -1 is out of range (0 to "), std::string::npos);
}

TEST_F(MissionReader, RefusesAnArcThatIsNotFromToAndKind) {
  std::string edited = reseal(replace_once(text_, arc_start(0), arc_start(0) + "7,8,"));
  EXPECT_NE(defects(edited).find("error: /arcs/0: an arc is [from, to, kind] or [from, to, kind, branch]"),
            std::string::npos)
      << defects(edited);
}

TEST_F(MissionReader, RefusesANodeHeldByADroneOutsideTheFleet) {
  std::string edited = reseal(replace_once(text_, "{\"meg\":0,", "{\"meg\":0,\"drone\":\"Ghost\","));
  EXPECT_EQ(defects(edited),
            "Drone1/mission.json: error: /nodes/0/drone: drone \"Ghost\" is not in the mission's fleet\n");
}

// A node that names its holder is another drone's: the file's own drone never names itself.
TEST_F(MissionReader, RefusesAnOwnNodeThatNamesItsDrone) {
  std::string edited = reseal(replace_once(text_, "{\"meg\":0,", "{\"meg\":0,\"drone\":\"Drone1\","));
  EXPECT_EQ(defects(edited), "Drone1/mission.json: error: /nodes/0/drone: names this file's own drone, whose nodes "
                             "leave \"drone\" out\n");
}

TEST_F(MissionReader, RefusesUnknownEnumValues) {
  std::string edited = reseal(replace_once(text_, "\"kind\":\"init\"", "\"kind\":\"teleport\""));
  edited = reseal(replace_once(edited, "\"failsafe\":\"land\"", "\"failsafe\":\"crash\""));
  std::string found = defects(edited);
  EXPECT_NE(found.find("error: /nodes/0/kind: unknown value \"teleport\" (expected one of: init, action, fork, "
                       "condition, terminal, pause, end)"),
            std::string::npos)
      << found;
  EXPECT_NE(found.find("error: /drone/failsafe: unknown value \"crash\" (expected one of: land, return_home, hover)"),
            std::string::npos)
      << found;
}

TEST_F(MissionReader, RefusesNumbersOutOfRangeAndNullForANumber) {
  // A NaN or infinity would have been written as null: JSON has neither.
  std::string edited = reseal(replace_once(text_, "\"battery\":87.5", "\"battery\":150.0"));
  edited = reseal(replace_once(edited, "\"max_speed\":5.5", "\"max_speed\":null"));
  edited = reseal(replace_once(edited, "\"line\":", "\"line\":-"));
  std::string found = defects(edited);
  EXPECT_NE(found.find("error: /drone/battery: 150.0 is out of range (finite, 0 to 100)"), std::string::npos)
      << found;
  EXPECT_NE(found.find("error: /drone/limits/max_speed: expected a number, found null"), std::string::npos) << found;
  EXPECT_NE(found.find("error: /nodes/0/line: -"), std::string::npos) << found;
}

TEST_F(MissionReader, ReadsTheSeparationAndPrioritiesAndRefusesAPriorityOutOfRange) {
  std::string list;
  for (std::size_t d = 0; d < doc_["fleet"].size(); ++d) list += (d ? "," : "") + std::to_string(doc_["fleet"].size() - d);
  std::string with = reseal(replace_once(
      text_, "\"reads\":", "\"separation\":{\"horizontal\":4.0,\"vertical\":2.5},\"priorities\":[" + list + "],\"reads\":"));
  dex::Mission m;
  std::vector<std::string> errors;
  ASSERT_TRUE(deploy::read_mission(with, "Drone1/mission.json", m, errors)) << errors.front();
  EXPECT_EQ(m.separation.horizontal_m, 4.0);
  EXPECT_EQ(m.separation.vertical_m, 2.5);
  ASSERT_EQ(m.priorities.size(), doc_["fleet"].size());
  EXPECT_EQ(m.priorities.get().back(), 1);
  std::string bad = reseal(replace_once(with, "\"priorities\":[", "\"priorities\":[0,"));
  EXPECT_NE(defects(bad).find("error: /priorities: holds"), std::string::npos) << defects(bad);
  bad = reseal(replace_once(with, "\"vertical\":2.5", "\"vertical\":-1"));
  EXPECT_NE(defects(bad).find("error: /separation/vertical: -1"), std::string::npos) << defects(bad);
  // Without them: the defaults, every drone ranked by its place.
  dex::Mission plain;
  ASSERT_TRUE(deploy::read_mission(text_, "Drone1/mission.json", plain, errors));
  EXPECT_EQ(plain.separation.horizontal_m, 2.0);
  EXPECT_TRUE(plain.priorities.empty());
}

TEST_F(MissionReader, RefusesAWholeNumberWrittenAsAFraction) {
  std::string edited = reseal(replace_once(text_, "{\"meg\":0,", "{\"meg\":0.5,"));
  EXPECT_NE(defects(edited).find("error: /nodes/0/meg: expected a whole number, found number"), std::string::npos);
}

TEST_F(MissionReader, RefusesAnOperatorWithTheWrongNumberOfOperands) {
  // Listing 2's Drone1 file holds a condition; give its top operator a third operand.
  std::size_t at = text_.find("\"condition\":{\"op\":\"");
  ASSERT_NE(at, std::string::npos);
  std::string edited = text_;
  edited.insert(text_.find("\"args\":[", at) + 8, "{\"num\":1.0},");
  std::string found = defects(reseal(edited));
  EXPECT_NE(found.find("/condition/op: no operator"), std::string::npos) << found;
  EXPECT_NE(found.find("takes 3 operands"), std::string::npos) << found;
}

TEST_F(MissionReader, RefusesExpressionsNestedDeeperThanTheCompilerAllows) {
  // 100,000 nested negations: reading them recursively would overflow the stack.
  std::string deep;
  for (int i = 0; i < 100000; ++i) deep += "{\"op\":\"-\",\"args\":[";
  deep += "{\"num\":1.0}";
  for (int i = 0; i < 100000; ++i) deep += "]}";
  std::size_t at = text_.find("\"args\":[{\"num\":");
  ASSERT_NE(at, std::string::npos);
  std::string edited = text_;
  edited.insert(at + 8, deep + ",");
  std::string found = defects(reseal(edited));
  EXPECT_NE(found.find("Drone1/mission.json: error: nested more than"), std::string::npos) << found.substr(0, 400);
}

TEST_F(MissionReader, RefusesTextThatIsNotJson) {
  EXPECT_NE(defects("{\"format\": ").find("Drone1/mission.json: error: not valid JSON (at byte "), std::string::npos);
  EXPECT_NE(defects("").find("not valid JSON"), std::string::npos);
}

TEST_F(MissionReader, RefusesANumberTooLargeForADouble) {
  // Found by fuzz_mission: the JSON parser throws out_of_range, not parse_error, for it.
  std::string edited = reseal(replace_once(text_, "\"battery\":87.5", "\"battery\":3e8447"));
  EXPECT_EQ(defects(edited), "Drone1/mission.json: error: not valid JSON: a number too large for a double\n");
}

TEST_F(MissionReader, RefusesAFileOfAnotherFormatVersion) {
  std::string edited = reseal(replace_once(text_, "\"format_version\":4", "\"format_version\":1"));
  EXPECT_EQ(defects(edited),
            "Drone1/mission.json: error: /format_version: format version 1 is not supported by this DEX (knows 4); "
            "compile the mission with a matching eamos\n");
}

TEST_F(MissionReader, ReportsEveryDefectAtOnce) {
  std::string edited = replace_once(text_, "\"battery\":87.5", "\"battery\":-1.0");
  edited = replace_once(edited, "\"kind\":\"init\"", "\"kind\":\"teleport\"");
  std::string found = defects(edited);  // not resealed: the hash is a third defect
  EXPECT_NE(found.find("/file_hash:"), std::string::npos) << found;
  EXPECT_NE(found.find("/drone/battery:"), std::string::npos) << found;
  EXPECT_NE(found.find("/nodes/0/kind:"), std::string::npos) << found;
}

TEST_F(MissionReader, StopsListingDefectsAfterFifty) {
  auto stress = test::compile_mission(test::stress_text(3000, 3));
  ASSERT_TRUE(stress);
  std::string edited = deploy::mission_text(*stress, 0, deploy::mission_hash(*stress));
  ASSERT_GT(json::parse(edited)["nodes"].size(), 60u);
  std::size_t at = 0;
  for (std::size_t i = 0; i < 60; ++i) {  // a negative MEG id in each of the first 60 nodes
    at = edited.find("{\"meg\":", at);
    ASSERT_NE(at, std::string::npos);
    at += 7;
    edited.insert(at, "-1");
  }
  dex::Mission m;
  std::vector<std::string> errors;
  EXPECT_FALSE(deploy::read_mission(edited, "f", m, errors));
  ASSERT_EQ(errors.size(), deploy::kMaxMissionDefects + 1);
  EXPECT_NE(errors.back().find("more defects not shown"), std::string::npos) << errors.back();
}

// `eamos run` reads its drones' texts without the members every file holds alike; such a
// text is no mission file, and read alone it is refused as one missing its fleet.
TEST_F(MissionReader, ATextThatLeavesItsFleetToAnEarlierReadIsRefusedAlone) {
  std::string text = deploy::mission_text(*c_, 1, deploy::mission_hash(*c_), deploy::FleetMembers::shared);
  EXPECT_EQ(defects(text), "Drone1/mission.json: error: member \"fleet\" is missing\n");
}

// Every drone's whole file holds the same `fleet` and `priorities`, byte for byte, so one
// process may read them once: each drone's mission is then what its file alone gives.
TEST(FleetMissions, ReadTogetherEachDroneHoldsWhatItsWholeFileHolds) {
  auto c = test::compile_mission(test::listing2_text(), std::string(test::kListing2Fleet) + "    priority: 1\n");
  ASSERT_TRUE(c);
  std::vector<dex::Mission> together;
  std::vector<std::string> errors;
  ASSERT_TRUE(deploy::read_compiled_missions(*c, together, errors)) << errors.front();
  ASSERT_EQ(together.size(), 3u);
  std::string hash = deploy::mission_hash(*c);
  json first = json::parse(deploy::mission_text(*c, 0, hash));
  ASSERT_TRUE(first.contains("priorities"));
  for (int d = 0; d < 3; ++d) {
    std::string text = deploy::mission_text(*c, d, hash);
    json whole = json::parse(text);
    EXPECT_EQ(whole["fleet"].dump(), first["fleet"].dump());
    EXPECT_EQ(whole["priorities"].dump(), first["priorities"].dump());
    dex::Mission alone;
    ASSERT_TRUE(deploy::read_mission(text, "f", alone, errors)) << errors.front();
    const dex::Mission& m = together[d];
    EXPECT_TRUE(m.fleet.same_as(together[0].fleet));
    EXPECT_EQ(m.fleet.get(), alone.fleet.get());
    EXPECT_EQ(m.priorities.get(), alone.priorities.get());
    EXPECT_EQ(m.priorities.get(), (std::vector<int>{1, 1, 3}));  // Drone2 ranks with Drone1
    EXPECT_EQ(m.self, alone.self);
    EXPECT_EQ(m.reads, alone.reads);
    EXPECT_EQ(m.hash, alone.hash);
    ASSERT_EQ(m.nodes.size(), alone.nodes.size());
    for (std::size_t i = 0; i < m.nodes.size(); ++i) {
      EXPECT_EQ(m.nodes[i].text, alone.nodes[i].text);
      EXPECT_EQ(m.nodes[i].drone, alone.nodes[i].drone);
      EXPECT_EQ(m.nodes[i].waits_count, alone.nodes[i].waits_count);
    }
    EXPECT_EQ(m.arcs.size(), alone.arcs.size());
    ASSERT_EQ(m.drone_sets.size(), alone.drone_sets.size());
    for (std::size_t s = 0; s < m.drone_sets.size(); ++s) EXPECT_EQ(m.drone_sets[s].get(), alone.drone_sets[s].get());
  }
}

TEST_F(MissionReader, RefusesAFileThatCannotBeRead) {
  dex::Mission m;
  std::vector<std::string> errors;
  EXPECT_FALSE(deploy::read_mission_file("/nonexistent/mission.json", m, errors));
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].rfind("/nonexistent/mission.json: error: cannot read", 0), 0u) << errors[0];
}

}  // namespace
// The site's rules travel in the drone's mission file: the DEX that flies it needs no fleet
// file to keep them.
TEST(MissionSite, TheGeofenceSpeedsAndGustSurviveWriteAndRead) {
  std::string fleet = std::string(test::kListing2Fleet) +
                      "    gust: {at: 4, for: 1.5, velocity: [2, 0, -0.5]}\n"
                      "safety:\n"
                      "  max_speed: 3.5\n"
                      "  geofence: {polygon: [[-40, -40], [40, -40], [40, 40], [-40, 40]], min_altitude: 1, "
                      "max_altitude: 25, upload: true}\n";
  auto c = test::compile_mission(test::listing2_text(), fleet);
  ASSERT_TRUE(c);
  int d2 = 1;
  std::string text = deploy::mission_text(*c, d2, deploy::mission_hash(*c));
  dex::Mission m;
  std::vector<std::string> errors;
  ASSERT_TRUE(deploy::read_mission(text, "Drone2/mission.json", m, errors)) << errors.front();
  const fleet::SiteLimits& site = m.settings.site;
  ASSERT_TRUE(site.geofence);
  EXPECT_EQ(site.geofence->polygon.size(), 4u);
  EXPECT_EQ(site.geofence->polygon[1], std::make_pair(40.0, -40.0));
  EXPECT_EQ(*site.geofence->min_altitude_m, 1.0);
  EXPECT_EQ(*site.geofence->max_altitude_m, 25.0);
  EXPECT_TRUE(site.geofence->upload);
  EXPECT_EQ(*site.max_speed_mps, 3.5);
  EXPECT_FALSE(site.max_climb_mps);
  ASSERT_TRUE(m.settings.gust);
  EXPECT_EQ(m.settings.gust->for_s, 1.5);
  EXPECT_EQ(m.settings.gust->velocity.z, -0.5);
}

TEST_F(MissionReader, AFileWithoutSafetyRulesHasNoSiteMember) {
  EXPECT_FALSE(doc_["drone"].contains("site"));
  EXPECT_FALSE(doc_["drone"].contains("gust"));
}

}  // namespace eamos
