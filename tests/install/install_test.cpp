// `cmake --install` into a clean prefix, then the prefix used as a user would: a C++
// program of its own built with find_package(eamos) compiles and flies a mission; the
// command, its man pages, the examples, the DEX's unit and the headers are all there.
#include <regex>
#include <set>

#include "install/shell.h"

namespace eamos {
namespace {

namespace fs = std::filesystem;
using eamos_test::shell_quote;
using eamos_test::sh;

class Install : public eamos_test::TempDir {
 protected:
  void SetUp() override {
    TempDir::SetUp();
    prefix_ = dir_ / "prefix";
    ASSERT_NO_FATAL_FAILURE(eamos_test::install_into(prefix_));
  }
  /// The subcommands `eamos --help` lists.
  std::vector<std::string> subcommands() {
    eamos_test::Shell help = sh(shell_quote((prefix_ / "bin/eamos").string()) + " --help");
    EXPECT_EQ(help.status, 0) << help.out;
    std::vector<std::string> subs;
    std::string listing = help.out.substr(help.out.find("\nSubcommands:\n"));
    std::regex line("\n  ([a-z][a-z0-9-]*)  +");
    for (std::sregex_iterator it(listing.begin(), listing.end(), line), end; it != end; ++it)
      subs.push_back((*it)[1]);
    return subs;
  }
  fs::path prefix_;
};

TEST_F(Install, ProgramBuiltAgainstTheInstalledPackageCompilesAndFliesAMission) {
  fs::path build = dir_ / "consumer";
  eamos_test::Shell configure =
      sh(std::string(EAMOS_CMAKE) + " -S " + shell_quote(EAMOS_CONSUMER_DIR) + " -B " + shell_quote(build.string()) +
         " -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_EXPORT_COMPILE_COMMANDS=ON -DCMAKE_PREFIX_PATH=" +
         shell_quote(prefix_.string()));
  ASSERT_EQ(configure.status, 0) << configure.out;
  eamos_test::Shell compile = sh(std::string(EAMOS_CMAKE) + " --build " + shell_quote(build.string()));
  ASSERT_EQ(compile.status, 0) << compile.out;
  // Its headers come from the prefix, never from the source tree.
  std::string commands = eamos_test::read_file(build / "compile_commands.json");
  EXPECT_NE(commands.find((prefix_ / "include/eamos").string()), std::string::npos) << commands;
  EXPECT_EQ(commands.find(std::string(EAMOS_SOURCE_DIR) + "/src"), std::string::npos) << commands;

  eamos_test::Shell run = sh(shell_quote((build / "fly_mission").string()));
  EXPECT_EQ(run.status, 0) << run.out;
  EXPECT_NE(run.out.find("built against eamos " EAMOS_VERSION_TEXT "\n"), std::string::npos) << run.out;
  EXPECT_TRUE(std::regex_search(run.out, std::regex("\ncompleted in [0-9.]+ s\n"))) << run.out;
}

TEST_F(Install, EveryHeaderAnInstalledHeaderIncludesIsInstalled) {
  fs::path include = prefix_ / "include/eamos";
  std::regex quoted_include("#include \"([^\"]+)\"");
  int headers = 0;
  for (const auto& entry : fs::recursive_directory_iterator(include)) {
    if (entry.path().extension() != ".h") continue;
    ++headers;
    std::string text = eamos_test::read_file(entry.path());
    for (std::sregex_iterator it(text.begin(), text.end(), quoted_include), end; it != end; ++it)
      EXPECT_TRUE(fs::exists(include / (*it)[1].str())) << entry.path() << " includes " << (*it)[1];
  }
  EXPECT_GT(headers, 50);
  // Private headers stay private: a third-party header's wrapper, the YAML reader.
  EXPECT_FALSE(fs::exists(include / "deploy/sha256.h"));
  EXPECT_FALSE(fs::exists(include / "fleet/yaml_reader.h"));
  EXPECT_TRUE(fs::exists(prefix_ / "lib/cmake/eamos/eamosConfig.cmake"));
  EXPECT_TRUE(fs::exists(prefix_ / "lib/cmake/eamos/eamosConfigVersion.cmake"));
}

TEST_F(Install, CommandHasAManPagePerSubcommandMadeFromItsHelp) {
  eamos_test::Shell version = sh(shell_quote((prefix_ / "bin/eamos").string()) + " --version");
  EXPECT_EQ(version.out, "eamos " EAMOS_VERSION_TEXT "\n");
  std::vector<std::string> subs = subcommands();
  ASSERT_GE(subs.size(), 10u);
  fs::path man = prefix_ / "share/man/man1";
  std::string top = eamos_test::read_file(man / "eamos.1");
  for (const std::string& sub : subs) {
    SCOPED_TRACE(sub);
    std::string page = eamos_test::read_file(man / ("eamos-" + sub + ".1"));
    EXPECT_NE(page.find(".SH NAME\neamos-" + sub + " \\- "), std::string::npos) << page.substr(0, 400);
    EXPECT_NE(top.find(".BR eamos-" + sub + " (1)"), std::string::npos);
  }
  // The options are the command's own: --package is on compile's page, as in its --help.
  EXPECT_NE(eamos_test::read_file(man / "eamos-compile.1").find("\\-\\-package"), std::string::npos);
  eamos_test::Shell rendered = sh("man -l " + shell_quote((man / "eamos-dex.1").string()) + " | head -5");
  EXPECT_NE(rendered.out.find("eamos-dex - Run one drone's DEX"), std::string::npos) << rendered.out;
}

TEST_F(Install, ExamplesUnitConfigurationAndCompletionsAreInstalled) {
  fs::path share = prefix_ / "share";
  eamos_test::Shell check = sh(shell_quote((prefix_ / "bin/eamos").string()) + " check -q " +
                               shell_quote((share / "eamos/examples/listing2.eamos").string()));
  EXPECT_EQ(check.status, 0) << check.out;
  // The compile's credentials come from libexec/eamos/eamos-credentials, installed beside eamos-fly.
  eamos_test::Shell compile = sh(shell_quote((prefix_ / "bin/eamos").string()) + " compile -q " +
                                 shell_quote((share / "eamos/examples/listing2.eamos").string()) + " -o " +
                                 shell_quote((dir_ / "deploy").string()));
  EXPECT_EQ(compile.status, 0) << compile.out;
  EXPECT_TRUE(fs::exists(prefix_ / "libexec/eamos/eamos-credentials"));
  EXPECT_TRUE(fs::exists(dir_ / "deploy/ground-station/security/permissions.p7s"));
  EXPECT_TRUE(fs::exists(share / "eamos/examples/listing2-right.yaml"));
  EXPECT_EQ(eamos_test::read_file(prefix_ / "lib/systemd/system/eamos-dex@.service"),
            eamos_test::read_file(std::string(EAMOS_SOURCE_DIR) + "/config/eamos-dex@.service"));
  EXPECT_TRUE(fs::exists(share / "eamos/config/cyclonedds-network.xml"));
  EXPECT_TRUE(fs::exists(share / "bash-completion/completions/eamos"));
  EXPECT_TRUE(fs::exists(share / "zsh/site-functions/_eamos"));
  EXPECT_TRUE(fs::exists(share / "doc/eamos/docs/deploy.md"));
}

}  // namespace
}  // namespace eamos
