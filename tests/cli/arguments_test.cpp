// The command line read as a compiler reads a source: the real binary, given wrong commands,
// options, values and output paths, names the argument, points at it and says the fix.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;

using eamos_test::Output;
Output eamos_in_source_dir(const std::string& args) { return eamos_test::run_eamos(args, {}, EAMOS_SOURCE_DIR); }

class Arguments : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eamos-args-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(Arguments, AMisspelledCommandGetsTheClosestWithACaretUnderIt) {
  Output r = eamos_in_source_dir("chek examples/listing2.eamos");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out,
            "eamos: error: unknown command 'chek'; did you mean 'check'?\n"
            " eamos chek examples/listing2.eamos\n"
            "       ^~~~\n");
}

TEST_F(Arguments, NoCommandListsTheCommands) {
  Output r = eamos_in_source_dir("");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("eamos: error: no command given; say what to do: eamos COMMAND …, where COMMAND is one of "
                       "check, compile, graph"),
            std::string::npos)
      << r.out;
}

TEST_F(Arguments, AMisspelledOptionGetsTheClosestOfItsCommand) {
  Output r = eamos_in_source_dir("run examples/listing2.eamos --trce t.jsonl");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out,
            "eamos: error: unknown option '--trce' of `eamos run`; did you mean '--trace'?\n"
            " eamos run examples/listing2.eamos --trce t.jsonl\n"
            "                                   ^~~~~~\n");
}

TEST_F(Arguments, AnOptionOfAnotherCommandSaysWhoseItIs) {
  Output r = eamos_in_source_dir("check examples/listing2.eamos --summary s.json");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("eamos: error: '--summary' is an option of `eamos run`, `eamos launch`, not of `eamos check`"),
            std::string::npos)
      << r.out;
}

TEST_F(Arguments, ANumberOutOfRangeIsStatedInWordsUnderItsValue) {
  Output r = eamos_in_source_dir("run examples/listing2.eamos --speed 0");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out,
            "eamos: error: --speed: '0' is not a number greater than 0\n"
            " eamos run examples/listing2.eamos --speed 0\n"
            "                                           ^\n");
  r = eamos_in_source_dir("run examples/listing2.eamos --domain=300 --distributed");
  EXPECT_NE(r.out.find("--domain: '300' is not a whole number from 0 to 230\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("                                   ^~~\n"), std::string::npos) << r.out;
  r = eamos_in_source_dir("run examples/listing2.eamos --telemetry-hz 101");
  EXPECT_NE(r.out.find("--telemetry-hz: '101' is not a number from 0 to 100"), std::string::npos) << r.out;
  r = eamos_in_source_dir("graph examples/listing2.eamos --kind megg");
  EXPECT_NE(r.out.find("--kind: 'megg' is not one of amt, meg, mdg; did you mean 'meg'?"), std::string::npos) << r.out;
}

TEST_F(Arguments, AMissingFileGetsTheCloseNameBesideIt) {
  Output r = eamos_in_source_dir("check examples/listing3.eamos");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("eamos: error: no file 'examples/listing3.eamos'; did you mean 'examples/listing2.eamos'?"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("             ^~~~~~~~~~~~~~~~~~~~~~~"), std::string::npos) << r.out;
}

TEST_F(Arguments, AMissingValueAndAMissingArgumentAreNamed) {
  Output r = eamos_in_source_dir("run examples/listing2.eamos --speed");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("eamos: error: --speed needs a value"), std::string::npos) << r.out;
  r = eamos_in_source_dir("compile examples/listing2.eamos");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("eamos: error: `eamos compile` needs --output (Output folder)"), std::string::npos) << r.out;
}

TEST_F(Arguments, EveryOutputPathIsCheckedBeforeAnythingFlies) {
  std::string nowhere = (dir_ / "no" / "such" / "folder").string();
  Output r = eamos_in_source_dir("run examples/listing2.eamos --plot " + nowhere + "/plot.svg --trace " + dir_.string() +
                   " --summary " + (dir_ / "s.json").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("eamos: error: --plot: the folder '" + nowhere + "' does not exist; create it (mkdir -p " +
                       nowhere + ") or write elsewhere"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("eamos: error: --trace: '" + dir_.string() + "' is a folder; give a file path"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("mission completed"), std::string::npos) << r.out;  // nothing flew
  EXPECT_FALSE(fs::exists(dir_ / "s.json"));
}

// `-o "$OUT"` with OUT unset: the compile wrote nowhere useful, and --trace "" was taken as no
// trace at all. An empty path is refused at its option, as any unusable output is.
TEST_F(Arguments, AnEmptyOutputPathIsRefusedAtItsOption) {
  Output r = eamos_in_source_dir("compile examples/listing2.eamos -o ''");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("eamos: error: --output: an empty path; name a folder (made if missing)"), std::string::npos)
      << r.out;
  r = eamos_in_source_dir("run examples/listing2.eamos --trace ''");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("eamos: error: --trace: an empty path; name a file, or leave the option out"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("mission completed"), std::string::npos) << r.out;  // nothing flew
}

TEST_F(Arguments, TwoOutputsToOneFileAndAnOutputOverTheMissionAreRefused) {
  std::string same = (dir_ / "out.json").string();
  Output r = eamos_in_source_dir("run examples/listing2.eamos --trace " + same + " --summary " + same);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("eamos: error: --summary: --trace writes '" + same + "' too; give each its own file"),
            std::string::npos)
      << r.out;
  fs::copy_file(fs::path(EAMOS_SOURCE_DIR) / "examples/listing2.eamos", dir_ / "m.eamos");
  r = eamos_in_source_dir("run " + (dir_ / "m.eamos").string() + " --plot " + (dir_ / "m.eamos").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("is an input of this command; writing it would destroy it"), std::string::npos) << r.out;
  EXPECT_GT(fs::file_size(dir_ / "m.eamos"), 1000u);
}

TEST_F(Arguments, AMissionWhereATraceOrADeploymentIsExpectedIsRecognised) {
  Output r = eamos_in_source_dir("monitor examples/listing2.eamos --port 0");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out,
            "eamos: error: 'examples/listing2.eamos' is a mission, not a trace; watch it fly with `eamos run "
            "examples/listing2.eamos --monitor 8080`, or record a trace with `eamos run examples/listing2.eamos "
            "--trace run.jsonl` and replay that\n");
  r = eamos_in_source_dir("launch examples/listing2.eamos");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("'examples/listing2.eamos' is a mission, not a deployment folder; compile it first"),
            std::string::npos)
      << r.out;
}

TEST_F(Arguments, ColourOnlyWhenAskedOrOnATerminal) {
  fs::path m = dir_ / "bad.eamos";
  std::ofstream(m) << "var A Quad\nfunc INIT() { A.Tkeoff(3) }\n";
  Output plain = eamos_in_source_dir("check " + m.string());
  EXPECT_EQ(plain.out.find("\x1b["), std::string::npos) << plain.out;  // a pipe: no colour
  Output coloured = eamos_in_source_dir("check " + m.string() + " --color=always");
  EXPECT_NE(coloured.out.find("\x1b[1;31merror:\x1b[0m"), std::string::npos) << coloured.out;
  EXPECT_NE(coloured.out.find("\x1b[1;32m^~~~~~\x1b[0m"), std::string::npos) << coloured.out;
  Output bad = eamos_in_source_dir("check " + m.string() + " --color=sometimes");
  EXPECT_NE(bad.out.find("--color: 'sometimes' is not one of auto, always, never"), std::string::npos) << bad.out;
}

TEST_F(Arguments, SarifLogHasTheResultsTheirRangesAndTheirNotes) {
  fs::path m = dir_ / "dup.eamos";
  std::ofstream(m) << "var Drone1 Quad\nfunc INIT() { SEQ_a() }\nfunc SEQ_a() { Drone1.Land() }\n"
                      "func SEQ_a() { Drone1.Land() }\n";
  std::string cmd = std::string(EAMOS_BINARY) + " check " + m.string() + " --diagnostics-format=sarif 2>/dev/null";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[4096];
  while (std::size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  EXPECT_EQ(WEXITSTATUS(pclose(p)), 1);
  nlohmann::json log = nlohmann::json::parse(out);  // standard output is the log alone
  EXPECT_EQ(log["version"], "2.1.0");
  const nlohmann::json& run = log["runs"][0];
  EXPECT_EQ(run["tool"]["driver"]["name"], "eamos");
  ASSERT_EQ(run["results"].size(), 1u) << out;
  const nlohmann::json& r = run["results"][0];
  EXPECT_EQ(r["level"], "error");
  const nlohmann::json& region = r["locations"][0]["physicalLocation"]["region"];
  EXPECT_EQ(region["startLine"], 4);
  EXPECT_EQ(region["startColumn"], 6);
  EXPECT_EQ(region["endColumn"], 11);  // SEQ_a
  EXPECT_EQ(r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"], "file://" + m.string());
  EXPECT_EQ(r["relatedLocations"][0]["message"]["text"], "first defined here");
  EXPECT_EQ(r["relatedLocations"][0]["physicalLocation"]["region"]["startLine"], 3);
}

TEST_F(Arguments, CountsArePluralOnlyAboveOne) {
  fs::path m = dir_ / "one.eamos";
  std::ofstream(m) << "var Drone1 Quad\nfunc INIT() { Drone1.Arm(); Drone1.Tkeoff(3) }\n";
  Output r = eamos_in_source_dir("check " + m.string());
  EXPECT_NE(r.out.find("\n1 error, 0 warnings\n"), std::string::npos) << r.out;
  std::ofstream(m) << "var Drone1 Quad\nfunc INIT() { Drone1.Arm(); Drone1.Takeoff(3); Drone1.Land(); Drone1.Disarm() }\n";
  r = eamos_in_source_dir("check " + m.string());
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find(": ok — 1 drone, "), std::string::npos) << r.out;
}

}  // namespace
