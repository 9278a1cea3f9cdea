// verify() as a library: what it finds in a hundred-drone mission, and that flying a path's
// timings side by side reports exactly what flying them one after another does.
#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>

#include "deploy/mission_file.h"
#include "graph/pipeline.h"
#include "verify/verify.h"

namespace eamos::verify {
namespace {

struct Compiled {
  graph::Compilation c;
  std::vector<dex::Mission> missions;
};

/// Compiles and reads every drone's mission file back, as `eamos verify` does.
std::unique_ptr<Compiled> compiled(const std::string& path, const std::string& fleet, const std::string& text = "") {
  auto out = std::make_unique<Compiled>();
  Diagnostics diags;
  bool ok = text.empty() ? graph::compile_file(path, fleet, diags, out->c)
                         : graph::compile(std::make_shared<SourceFile>(path, text), fleet::Fleet{}, diags, out->c);
  if (!ok) throw std::runtime_error(diags.format());
  std::string hash = deploy::mission_hash(out->c);
  out->missions.resize(out->c.drone_count());
  for (int d = 0; d < out->c.drone_count(); ++d) {
    std::vector<std::string> errors;
    if (!deploy::read_mission(deploy::mission_text(out->c, d, hash), path, out->missions[d], errors))
      throw std::runtime_error(errors.front());
  }
  return out;
}

std::string y_of(int drone) { return std::to_string(5.0 * drone); }  // default homes: (0, 5 i, 0)

/// 100 drones take off from their default homes 5 m apart and fly east in parallel lanes;
/// D40 and D41 swap lanes (they meet half way). D70 waits at (-0.9, 352.5) while D71 comes to
/// (0.9, 352.5): 1.8 m apart on either side of x = 0, a boundary between cells of any width;
/// in a grid of cells narrower than the separation they would never be in neighbouring cells.
std::string hundred_drones() {
  std::string text = "package hundred\n";
  for (int d = 0; d < 100; ++d) text += "var D" + std::to_string(d) + " Quad\n";
  text += "func INIT() { PAR_all() }\nfunc PAR_all() {";
  for (int d = 0; d < 100; ++d) text += " SEQ_d" + std::to_string(d) + "();";
  text += " }\n";
  for (int d = 0; d < 100; ++d) {
    std::string D = "D" + std::to_string(d), lane = y_of(d == 40 ? 41 : d == 41 ? 40 : d);
    std::string first = D + ".FlyTo(10, " + lane + ", 5); ";
    if (d == 70) first = D + ".FlyTo(-0.9, 352.5, 5); " + D + ".Hover(20); ";
    if (d == 71) first = D + ".Hover(10); " + D + ".FlyTo(0.9, 352.5, 5); ";
    text += "func SEQ_d" + std::to_string(d) + "() { " + D + ".Arm(); " + D + ".Takeoff(5); " + first + D +
            ".FlyTo(20, " + lane + ", 5); " + D + ".Land(); " + D + ".Disarm() }\n";
  }
  return text;
}

TEST(VerifyHundredDrones, FindsTheTwoPairsThatMeetAndNoOther) {
  auto m = compiled("hundred.eamos", "", hundred_drones());
  VerifyReport r = verify(m->c, m->missions);
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.paths, 1);
  ASSERT_EQ(r.violations.size(), 2u) << format_report(m->c, r);
  for (const Violation& v : r.violations) EXPECT_EQ(v.kind, "separation") << v.at.message;
  std::vector<std::set<std::string>> pairs;
  for (const Violation& v : r.violations) pairs.emplace_back(v.drones.begin(), v.drones.end());
  EXPECT_NE(std::find(pairs.begin(), pairs.end(), std::set<std::string>{"D40", "D41"}), pairs.end());
  EXPECT_NE(std::find(pairs.begin(), pairs.end(), std::set<std::string>{"D70", "D71"}), pairs.end());
}

// The timing missions: several timings per path, violations on some of them only.
TEST(VerifyJobs, FlyingTimingsSideBySideReportsWhatFlyingThemInTurnReports) {
  struct Case {
    std::string mission, fleet;
    bool jitter;
  };
  std::string examples = EAMOS_SOURCE_DIR "/examples/";
  for (const Case& k : {Case{EAMOS_TEST_DATA "/missions/timing.eamos", "", false},
                        Case{examples + "listing2.eamos", examples + "listing2-range.yaml", true},
                        Case{examples + "relay.eamos", "", true}}) {
    auto m = compiled(k.mission, k.fleet);
    VerifyOptions one, several;
    one.jobs = 1;
    several.jobs = 3;
    one.jitter = several.jitter = k.jitter;
    VerifyReport in_turn = verify(m->c, m->missions, one);
    VerifyReport side_by_side = verify(m->c, m->missions, several);
    EXPECT_GT(in_turn.paths, 2) << k.mission;
    EXPECT_EQ(format_report(m->c, side_by_side), format_report(m->c, in_turn)) << k.mission;
    EXPECT_EQ(json_report(m->c, side_by_side), json_report(m->c, in_turn)) << k.mission;
    EXPECT_EQ(side_by_side.worst.number, in_turn.worst.number) << k.mission;
    // A bound that falls inside a batch stops at the same flight.
    one.max_paths = several.max_paths = in_turn.paths - 1;
    EXPECT_EQ(format_report(m->c, verify(m->c, m->missions, several)), format_report(m->c, verify(m->c, m->missions, one)))
        << k.mission;
  }
}

// The missions of one process may share the fleet's tables (deploy::read_compiled_missions, and
// `eamos verify` building them in memory), a library user's may not: the flights, and so the paths, must not depend on it. Listing 2's RepeatWhile
// reads Drone3 while it takes off, so each outcome of its If is flown nominal and with Drone3
// 25 % slower and faster: 6 paths (tests/verify/examples records the same through the CLI).
TEST(VerifyLibrary, FliesTheSamePathsWhetherOrNotTheMissionsShareTheirTables) {
  std::string examples = EAMOS_SOURCE_DIR "/examples/";
  auto own = compiled(examples + "listing2.eamos", examples + "listing2-range.yaml");
  auto shared = compiled(examples + "listing2.eamos", examples + "listing2-range.yaml");
  std::vector<std::string> errors;
  ASSERT_TRUE(deploy::read_compiled_missions(shared->c, shared->missions, errors)) << errors.front();
  VerifyReport a = verify(own->c, own->missions), b = verify(shared->c, shared->missions);
  EXPECT_EQ(a.paths, 6);
  EXPECT_EQ(format_report(own->c, a), format_report(shared->c, b));
}

}  // namespace
}  // namespace eamos::verify
