// The shell completions (packaging/eamos.bash, packaging/_eamos), loaded in a real bash and
// zsh beside the eamos under test, complete from that command's own help.
#include "install/shell.h"

namespace eamos {
namespace {

namespace fs = std::filesystem;
using eamos_test::shell_quote;
using eamos_test::sh;

/// What the bash completion offers for the words of a command line (the last one is being
/// completed), run in the examples folder.
std::string bash_complete(const std::string& words) {
  std::string script = "PATH=" + shell_quote(fs::path(EAMOS_BINARY).parent_path().string()) + ":$PATH\n" +
                       "source " + shell_quote(std::string(EAMOS_SOURCE_DIR) + "/packaging/eamos.bash") + "\n" +
                       "cd " + shell_quote(std::string(EAMOS_SOURCE_DIR) + "/examples") + "\n" +
                       "COMP_WORDS=(" + words + "); COMP_CWORD=$((${#COMP_WORDS[@]} - 1))\n" +
                       "_eamos; for w in \"${COMPREPLY[@]}\"; do echo \"$w\"; done | sort\n";
  eamos_test::Shell r = sh("bash --norc -c " + shell_quote(script));
  EXPECT_EQ(r.status, 0) << r.out;
  return r.out;
}

TEST(BashCompletion, CompletesSubcommandsFromTheCommandsHelp) {
  EXPECT_EQ(bash_complete("eamos co"), "compile\n");
  std::string all = bash_complete("eamos ''");
  for (const char* sub : {"check", "compile", "run", "verify", "launch", "dex", "sim-vehicle", "--version"})
    EXPECT_NE(all.find(std::string(sub) + "\n"), std::string::npos) << sub << " in\n" << all;
}

TEST(BashCompletion, CompletesTheOptionsOfTheSubcommandBeingTyped) {
  EXPECT_EQ(bash_complete("eamos compile --pa"), "--package\n");
  EXPECT_EQ(bash_complete("eamos run m.eamos --tel"), "--telemetry-hz\n");
  EXPECT_EQ(bash_complete("eamos check --pa"), "");
}

TEST(BashCompletion, CompletesTheValuesAnOptionAccepts) {
  EXPECT_EQ(bash_complete("eamos graph m.eamos --kind ''"), "amt\nmdg\nmeg\n");
  EXPECT_EQ(bash_complete("eamos sim-vehicle --autopilot a"), "ardupilot\n");
  // A number takes nothing to complete; a flag takes no value, so a positional follows it.
  EXPECT_EQ(bash_complete("eamos compile --valid-days ''"), "");
  EXPECT_EQ(bash_complete("eamos compile --insecure list"), "listing2.eamos\n");
}

TEST(BashCompletion, CompletesMissionsFleetFilesAndFoldersWhereTheyAreExpected) {
  EXPECT_EQ(bash_complete("eamos run p"), "patrol.eamos\n");
  EXPECT_EQ(bash_complete("eamos run listing2.eamos --fleet listing2-r"), "listing2-range.yaml\nlisting2-right.yaml\n");
  EXPECT_EQ(bash_complete("eamos launch ../con"), "../config\n");
  EXPECT_EQ(bash_complete("eamos run listing2.eamos --fleet ../con"), "../config\n") << "a folder may hold it";
}

TEST(ZshCompletion, DescribesEachOptionWithWhatItTakes) {
  std::string script = "PATH=" + shell_quote(fs::path(EAMOS_BINARY).parent_path().string()) + ":$PATH\n" +
                       "source " + shell_quote(std::string(EAMOS_SOURCE_DIR) + "/packaging/_eamos") + "\n" +
                       "_eamos_specs graph\n";
  eamos_test::Shell r = sh("zsh -f -c " + shell_quote(script));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("--kind[amt | meg | mdg]:kind:(amt meg mdg)\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--fleet[Fleet file (YAML): drone types and per-drone settings]:fleet:_files -g '*.(yaml|yml)'\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("--werror[Treat warnings as errors]\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(-o --output)-o[Output file (default: standard output)]:output:_files\n"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("1:mission:_files -g '*.eamos'\n"), std::string::npos) << r.out;
}

TEST(ZshCompletion, RegistersItselfWhenSourcedAfterCompinit) {
  std::string script = "PATH=" + shell_quote(fs::path(EAMOS_BINARY).parent_path().string()) + ":$PATH\n" +
                       "autoload -Uz compinit && compinit -u -D\n" +
                       "source " + shell_quote(std::string(EAMOS_SOURCE_DIR) + "/packaging/_eamos") + "\n" +
                       "print -r -- ${_comps[eamos]}\n";
  eamos_test::Shell r = sh("zsh -f -c " + shell_quote(script));
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(r.out, "_eamos\n");
}

}  // namespace
}  // namespace eamos
