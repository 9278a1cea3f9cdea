// `eamos verify` end to end, through the real binary. One mission per rule under
// tests/verify/missions/: NAME.eamos (with NAME.fleet.yaml and NAME.args when present) next
// to NAME.expected, the exact text `eamos verify` prints in that folder. Each NAME has a
// twin NAME_fixed that keeps the mission's intent and verifies clean (exit 0).
// Regenerate after an intended change with EAMOS_UPDATE_GOLDEN=1 and review the diff.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "trace/trace_schema.h"
#include "support/run_eamos.h"

namespace eamos {
namespace {

namespace fs = std::filesystem;

const fs::path kMissions = fs::path(EAMOS_TEST_DATA) / "missions";

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> cases() {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(kMissions))
    if (e.path().extension() == ".eamos") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string arguments(const std::string& name) {
  std::string args = name + ".eamos";
  if (fs::exists(kMissions / (name + ".fleet.yaml"))) args += " --fleet " + name + ".fleet.yaml";
  if (fs::exists(kMissions / (name + ".args"))) {
    std::string extra = read_file(kMissions / (name + ".args"));
    extra.erase(std::remove(extra.begin(), extra.end(), '\n'), extra.end());
    args += " " + extra;
  }
  return args;
}

bool is_fixed_twin(const std::string& name) { return name.size() > 6 && name.substr(name.size() - 6) == "_fixed"; }

class VerifyMission : public ::testing::TestWithParam<std::string> {};

TEST_P(VerifyMission, EamosVerifyPrintsExpectedOutput) {
  std::string name = GetParam();
  eamos_test::Output run = eamos_test::run_eamos("verify " + arguments(name), {}, kMissions.string());
  ASSERT_NE(run.status, -1) << name << ": eamos did not exit normally (a signal?)\n" << run.out;
  bool has_error = run.out.find(": error: ") != std::string::npos;
  EXPECT_EQ(run.status, has_error ? 1 : 0) << name << ":\n" << run.out;
  // Every rule's mission breaks it; every twin keeps to all of them.
  EXPECT_EQ(has_error, !is_fixed_twin(name)) << name << ":\n" << run.out;
  fs::path expected = kMissions / (name + ".expected");
  if (std::getenv("EAMOS_UPDATE_GOLDEN")) {
    std::ofstream(expected, std::ios::binary) << run.out;
    return;
  }
  EXPECT_EQ(read_file(expected), run.out) << "for " << name;
}

TEST(VerifyMissions, EveryRuleMissionHasAFixedTwin) {
  for (const std::string& name : cases())
    if (!is_fixed_twin(name)) {
      EXPECT_TRUE(fs::exists(kMissions / (name + "_fixed.eamos"))) << name;
    }
}

INSTANTIATE_TEST_SUITE_P(Files, VerifyMission, ::testing::ValuesIn(cases()),
                         [](const auto& info) { return info.param; });

TEST(VerifyJson, ReportsEachViolationWithItsKindLineAndPath) {
  eamos_test::Output run =
      eamos_test::run_eamos("verify --json branch.eamos --fleet branch.fleet.yaml", {}, kMissions.string());
  EXPECT_EQ(run.status, 1);
  nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["paths"], 2);
  EXPECT_TRUE(j["complete"]);
  ASSERT_EQ(j["violations"].size(), 1u);
  const auto& v = j["violations"][0];
  EXPECT_EQ(v["kind"], "separation");
  EXPECT_EQ(v["line"], 14);
  ASSERT_EQ(v["path"].size(), 1u);
  EXPECT_EQ(v["path"][0]["value"], false);
  EXPECT_EQ(v["path"][0]["forced"], true);
}

TEST(VerifyPlot, MarksEachViolationOfTheDrawnPathInRed) {
  fs::path svg = fs::temp_directory_path() / ("verify_plot_" + std::to_string(::getpid()) + ".svg");
  eamos_test::Output run = eamos_test::run_eamos(
      "verify occupied_home.eamos --fleet occupied_home.fleet.yaml --plot " + svg.string(), {}, kMissions.string());
  EXPECT_EQ(run.status, 1) << run.out;
  std::string picture = read_file(svg);
  fs::remove(svg);
  std::size_t rings = 0;
  for (std::size_t at = 0; (at = picture.find("<circle data-violation=\"occupied_home\"", at)) != std::string::npos; ++at)
    ++rings;
  EXPECT_EQ(rings, 3u) << "one ring per violation on the map";
  EXPECT_NE(picture.find("<line data-violation=\"occupied_home\""), std::string::npos);
}

// The trace of the drawn path carries one violation event per broken rule, at the line the
// diagnostic names, and still passes the schema (strict: the kind is documented).
TEST(VerifyTrace, WritesThePathWithAViolationEventAtTheResponsibleLine) {
  fs::path trace = fs::temp_directory_path() / ("verify_trace_" + std::to_string(::getpid()) + ".jsonl");
  eamos_test::Output run = eamos_test::run_eamos(
      "verify separation.eamos --fleet separation.fleet.yaml --trace " + trace.string(), {}, kMissions.string());
  EXPECT_EQ(run.status, 1) << run.out;
  std::string text = read_file(trace);
  fs::remove(trace);
  std::istringstream in(text);
  EXPECT_EQ(eamos::trace::check_trace(in, {.strict = true}), std::vector<std::string>{});
  std::vector<nlohmann::json> violations;
  bool has_actions = false;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.value("event", "") == "violation") violations.push_back(j);
    if (j.value("event", "") == "start") has_actions = true;
  }
  EXPECT_TRUE(has_actions) << "the flight itself is in the trace";
  ASSERT_EQ(violations.size(), 1u) << text;
  EXPECT_EQ(violations[0]["kind"], "separation");
  EXPECT_EQ(violations[0]["drone"], "Drone1");
  EXPECT_EQ(violations[0]["line"], 8);
  EXPECT_EQ(violations[0]["col"], 19);
  EXPECT_EQ(violations[0]["drones"], nlohmann::json::array({"Drone2"}));
  EXPECT_DOUBLE_EQ(violations[0]["t"].get<double>(), 3.75);
  EXPECT_NE(violations[0]["text"].get<std::string>().find("come within 1.88 m"), std::string::npos);
}

// The monitor drew every drone of a verify trace at its home under "mission completed": the
// trace now says what it is (header) and where the drones flew (telemetry, as a run's trace).
TEST(VerifyTrace, SaysItIsAVerificationAndCarriesTheDronesPositions) {
  fs::path trace = fs::temp_directory_path() / ("verify_trace_pos_" + std::to_string(::getpid()) + ".jsonl");
  eamos_test::Output run = eamos_test::run_eamos(
      "verify separation.eamos --fleet separation.fleet.yaml --trace " + trace.string(), {}, kMissions.string());
  EXPECT_EQ(run.status, 1) << run.out;
  std::string text = read_file(trace);
  fs::remove(trace);
  std::istringstream lines(text);
  std::string first;
  std::getline(lines, first);
  nlohmann::json header = nlohmann::json::parse(first, nullptr, false);
  ASSERT_TRUE(header.is_object()) << first;
  EXPECT_EQ(header["run"], "verify");
  EXPECT_EQ(header["path"], 1);
  EXPECT_EQ(header["paths"], 1);
  EXPECT_EQ(header["violations"], 1);
  EXPECT_EQ(header["telemetry_hz"], 5.0);
  std::map<std::string, std::vector<nlohmann::json>> samples;
  nlohmann::json violation;
  for (std::string line; std::getline(lines, line);) {
    nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.value("event", "") == "telemetry") samples[j["drone"].get<std::string>()].push_back(j);
    if (j.value("event", "") == "violation") violation = j;
  }
  ASSERT_EQ(samples.size(), 2u);
  // Drone1 flies from (0, 0) to (0, 10) at 5 m: where it was at the violation is a sample's place.
  const nlohmann::json* at = nullptr;
  for (const auto& s : samples["Drone1"])
    if (s["t"].get<double>() <= violation["t"].get<double>() + 1e-9) at = &s;
  ASSERT_NE(at, nullptr);
  EXPECT_GT((*at)["y"].get<double>(), 2.0);
  EXPECT_LT((*at)["y"].get<double>(), 8.0);
  EXPECT_NEAR((*at)["z"].get<double>(), 5.0, 0.1);
  EXPECT_NEAR((*at)["y"].get<double>(), violation["y"].get<double>(), 1.0);
  EXPECT_NEAR(samples["Drone2"].back()["y"].get<double>(), 0.0, 0.6) << "Drone2 ends at Drone1's home";
}

// branch.eamos breaks a rule only when its If is forced the other way (the second path): the
// picture shows that path, not the clean first one, and says which combination it is.
TEST(VerifyPlot, DrawsThePathWithTheMostViolationsAndNamesItsCombination) {
  fs::path svg = fs::temp_directory_path() / ("verify_worst_" + std::to_string(::getpid()) + ".svg");
  eamos_test::Output run = eamos_test::run_eamos("verify branch.eamos --fleet branch.fleet.yaml --plot " + svg.string(),
                                                 {}, kMissions.string());
  EXPECT_EQ(run.status, 1) << run.out;
  std::string picture = read_file(svg);
  fs::remove(svg);
  EXPECT_NE(picture.find("<circle data-violation=\"separation\""), std::string::npos);
  EXPECT_NE(picture.find("Path 2 of 2 flown, 1 violation (the path with the most): Drone1.Sensor1() &gt;= 100 "
                         "(Drone1) false, forced"),
            std::string::npos)
      << picture.substr(0, 600);
}

TEST(VerifyPaths, StopsAtTheBoundAndSaysTheExplorationIsIncomplete) {
  eamos_test::Output run =
      eamos_test::run_eamos("verify --paths 1 branch.eamos --fleet branch.fleet.yaml", {}, kMissions.string());
  EXPECT_EQ(run.status, 0) << run.out;  // the one path flown (east) is clean
  EXPECT_NE(run.out.find("branch.eamos: 0 violations on 1 path flown; exploration incomplete"), std::string::npos) << run.out;
}

TEST(VerifyInput, AMissionWithErrorsIsNotFlown) {
  eamos_test::Output run = eamos_test::run_eamos("verify missing_block.eamos", {}, (fs::path(EAMOS_TEST_DATA) / "bad").string());
  EXPECT_EQ(run.status, 1);
  EXPECT_NE(run.out.find("missing_block.eamos:4:15: error: "), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find(" flown"), std::string::npos) << run.out;
}

// The shipped examples: each verifies with exactly the findings examples/*.expected records
// (docs/verify.md explains each one).
class VerifyExample : public ::testing::TestWithParam<std::string> {};

TEST_P(VerifyExample, MatchesItsRecordedFindings) {
  std::string args = GetParam();
  fs::path examples = fs::path(EAMOS_SOURCE_DIR) / "examples";
  std::string golden;
  for (char ch : args) golden += std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
  eamos_test::Output run = eamos_test::run_eamos("verify -q " + args, {}, examples.string());
  ASSERT_NE(run.status, -1) << run.out;
  bool has_error = run.out.find(": error: ") != std::string::npos;
  EXPECT_EQ(run.status, has_error ? 1 : 0) << run.out;
  fs::path expected = fs::path(EAMOS_TEST_DATA) / "examples" / (golden + ".expected");
  if (std::getenv("EAMOS_UPDATE_GOLDEN")) {
    std::ofstream(expected, std::ios::binary) << run.out;
    return;
  }
  EXPECT_EQ(read_file(expected), run.out) << "for " << args;
}

INSTANTIATE_TEST_SUITE_P(Examples, VerifyExample,
                         ::testing::Values("listing2.eamos", "listing2.eamos --fleet listing2-left.yaml",
                                           "listing2.eamos --fleet listing2-right.yaml",
                                           "listing2.eamos --fleet listing2-range.yaml --jitter", "patrol.eamos",
                                           "patrol.eamos --jitter",
                                           "patrol.eamos --fleet ../tests/cli/data/patrol-low-battery.yaml", "relay.eamos", "relay.eamos --jitter",
                                           "survey.eamos", "survey.eamos --jitter"),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& ch : n)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return n;
                         });

}  // namespace
}  // namespace eamos
