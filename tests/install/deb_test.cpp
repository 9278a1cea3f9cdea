// `cpack -G DEB` builds eamos and eamos-dev; the runtime package, unpacked with `dpkg -x` (no
// root, no container), runs its own command and an installed example, and its Depends name
// the Debian package of every shared library the command links.
#include <regex>
#include <set>

#include "install/shell.h"

namespace eamos {
namespace {

namespace fs = std::filesystem;
using eamos_test::shell_quote;
using eamos_test::sh;

class DebianPackage : public eamos_test::TempDir {
 protected:
  void SetUp() override {
    TempDir::SetUp();
    eamos_test::Shell cpack = sh(std::string(EAMOS_CPACK) + " -G DEB --config " +
                                 shell_quote(std::string(EAMOS_BUILD_DIR) + "/CPackConfig.cmake") + " -B " +
                                 shell_quote(dir_.string()));
    ASSERT_EQ(cpack.status, 0) << cpack.out;
    for (const auto& e : fs::directory_iterator(dir_)) {
      std::string name = e.path().filename().string();
      if (name.starts_with("eamos_" EAMOS_VERSION_TEXT "_")) runtime_ = e.path();
      if (name.starts_with("eamos-dev_" EAMOS_VERSION_TEXT "_")) dev_ = e.path();
    }
    ASSERT_FALSE(runtime_.empty()) << cpack.out;
    ASSERT_FALSE(dev_.empty()) << cpack.out;
  }
  std::string field(const fs::path& deb, const std::string& name) {
    eamos_test::Shell r = sh("dpkg-deb -f " + shell_quote(deb.string()) + " " + name);
    EXPECT_EQ(r.status, 0) << r.out;
    return r.out;
  }
  fs::path runtime_, dev_;
};

/// The Debian packages that own the shared libraries `binary` links directly (its NEEDED
/// entries, where ldd finds them, and dpkg -S); what those load in turn their packages depend on.
std::set<std::string> packages_linked_by(const std::string& binary) {
  eamos_test::Shell needed = sh("readelf -d " + shell_quote(binary));
  eamos_test::Shell ldd = sh("ldd " + shell_quote(binary));
  EXPECT_EQ(needed.status, 0) << needed.out;
  EXPECT_EQ(ldd.status, 0) << ldd.out;
  std::set<std::string> packages;
  std::regex entry("\\(NEEDED\\) +Shared library: \\[([^\\]]+)\\]");
  for (std::sregex_iterator it(needed.out.begin(), needed.out.end(), entry), end; it != end; ++it) {
    std::string name = (*it)[1];
    std::smatch where;
    if (!std::regex_search(ldd.out, where, std::regex(std::regex_replace(name, std::regex("[.+]"), "\\$&") +
                                                       " => (/[^ ]+) \\("))) {
      ADD_FAILURE() << name << " not found by ldd:\n" << ldd.out;
      continue;
    }
    // dpkg knows a library by the path its package installed (/lib or /usr/lib).
    std::string path = where[1];
    eamos_test::Shell owner =
        sh("dpkg -S " + shell_quote(path) + " 2>/dev/null || dpkg -S " + shell_quote("*/" + name) + " | head -1");
    EXPECT_EQ(owner.status, 0) << path << ": " << owner.out;
    packages.insert(owner.out.substr(0, owner.out.find(':')));
  }
  return packages;
}

TEST_F(DebianPackage, UnpackedCommandFliesAnInstalledExample) {
  fs::path root = dir_ / "root";
  eamos_test::Shell unpack = sh("dpkg -x " + shell_quote(runtime_.string()) + " " + shell_quote(root.string()));
  ASSERT_EQ(unpack.status, 0) << unpack.out;
  std::string eamos = (root / "usr/bin/eamos").string();
  EXPECT_EQ(sh(shell_quote(eamos) + " --version").out, "eamos " EAMOS_VERSION_TEXT "\n");
  fs::path examples = root / "usr/share/eamos/examples";
  eamos_test::Shell run = sh(shell_quote(eamos) + " run -q " + shell_quote((examples / "listing2.eamos").string()) +
                             " --fleet " + shell_quote((examples / "listing2-right.yaml").string()));
  EXPECT_EQ(run.status, 0) << run.out;
  EXPECT_TRUE(std::regex_search(run.out, std::regex("\nmission completed in [0-9.]+ s"))) << run.out;
  for (const char* file : {"usr/lib/systemd/system/eamos-dex@.service", "usr/share/man/man1/eamos-dex.1.gz",
                           "usr/share/bash-completion/completions/eamos", "usr/share/zsh/vendor-completions/_eamos"})
    EXPECT_TRUE(fs::exists(root / file) || fs::exists(root / fs::path(file).replace_extension())) << file;
  EXPECT_TRUE(fs::exists(root / "usr/libexec/eamos/eamos-fly")) << "`eamos run` above ran it";
  fs::path deploy = dir_ / "deploy";
  eamos_test::Shell compile = sh(shell_quote(eamos) + " compile -q " + shell_quote((examples / "listing2.eamos").string()) +
                                 " -o " + shell_quote(deploy.string()));
  EXPECT_EQ(compile.status, 0) << compile.out;
  EXPECT_TRUE(fs::exists(deploy / "Drone1/security/identity_key.pem")) << "made by usr/libexec/eamos/eamos-credentials";
  EXPECT_FALSE(fs::exists(root / "usr/include")) << "headers belong to eamos-dev";
}

TEST_F(DebianPackage, DependsOnThePackageOfEverySharedLibraryTheCommandLinks) {
  std::string depends = field(runtime_, "Depends");
  // `eamos` and eamos-fly, to which it hands the commands that fly (src/cli/CMakeLists.txt).
  std::set<std::string> loaded = packages_linked_by(std::string(EAMOS_BINARY));
  loaded.merge(packages_linked_by(std::string(EAMOS_FLY_BINARY)));
  // The ones a user would name: DDS, YAML, TLS, hashing, the monitor's web server.
  for (const char* expected : {"libddsc0debian", "libyaml-cpp0.7", "libssl3", "libnettle8", "libstdc++6", "libc6"})
    EXPECT_TRUE(loaded.count(expected)) << expected << " not linked by eamos or eamos-fly?";
  for (const std::string& package : loaded)
    EXPECT_TRUE(std::regex_search(depends, std::regex("(^|, )" + std::regex_replace(package, std::regex("[.+]"), "\\$&") + "( \\(|,|$|\n)")))
        << package << " missing from Depends: " << depends;
  EXPECT_NE(field(runtime_, "Recommends").find("graphviz"), std::string::npos);
}

TEST_F(DebianPackage, DevPackageHoldsTheCMakePackageAndDependsOnWhatItFinds) {
  std::string depends = field(dev_, "Depends");
  for (const char* expected : {"eamos (= " EAMOS_VERSION_TEXT ")", "nlohmann-json3-dev", "libyaml-cpp-dev",
                               "nettle-dev", "libssl-dev", "pkg-config"})
    EXPECT_NE(depends.find(expected), std::string::npos) << expected << " in " << depends;
  eamos_test::Shell contents = sh("dpkg-deb -c " + shell_quote(dev_.string()));
  EXPECT_TRUE(std::regex_search(contents.out, std::regex("/usr/lib/[^ ]*cmake/eamos/eamosConfig\\.cmake\n")))
      << contents.out;
  EXPECT_NE(contents.out.find("/usr/include/eamos/dex/runner.h"), std::string::npos);
  EXPECT_EQ(contents.out.find("/usr/bin/eamos"), std::string::npos);
}

}  // namespace
}  // namespace eamos
