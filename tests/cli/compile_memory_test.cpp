// The peak resident memory of the whole `eamos compile` process (docs/performance.md, "Against
// the paper"): bytes, not time, so the bounds hold on a loaded machine.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;

struct Peak {
  long kib = -1;
  int status = -1;
};

/// `program_and_args` through the small launcher, so that its peak is the program's own.
Peak peak_with(const std::string& program_and_args) {
  std::string cmd = std::string(EAMOS_PEAK_RSS) + " " + program_and_args;
  Peak p;
  FILE* f = popen(cmd.c_str(), "r");
  if (!f) return p;
  if (std::fscanf(f, "peak_kib %ld status %d", &p.kib, &p.status) != 2) p.kib = -1;
  pclose(f);
  return p;
}

/// `eamos args` through the small launcher.
Peak peak_of(const std::string& args) { return peak_with(std::string(EAMOS_BINARY) + " " + args); }

class CompileMemory : public ::testing::Test {
 protected:
  void SetUp() override {
#ifdef EAMOS_SANITIZED
    GTEST_SKIP() << "a sanitizer's shadow memory and quarantine are not the product's memory";
#endif
    dir_ = fs::temp_directory_path() / ("eamos-compile-memory-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    mission_ = (dir_ / "small.eamos").string();
    ASSERT_EQ(eamos_test::run_eamos("gen-stress --drones 20 --nodes 5000 -o " + mission_).status, 0);
  }
  void TearDown() override { fs::remove_all(dir_); }
  Peak compile(const std::string& extra) {
    fs::remove_all(dir_ / "out");
    return peak_of("compile " + mission_ + " -o " + (dir_ / "out").string() + " -q " + extra);
  }
  fs::path dir_;
  std::string mission_;
};

TEST_F(CompileMemory, TheCredentialsAddNothingToTheCompilesPeak) {
  // They need only the mission hash and the drones' names, so they are made once the graphs'
  // memory is given back; made beside the graphs, OpenSSL's pages added about 2.6 MB here.
  Peak insecure = compile("--insecure");
  Peak secure = compile("");
  ASSERT_EQ(insecure.status, 0);
  ASSERT_EQ(secure.status, 0);
  ASSERT_TRUE(fs::exists(dir_ / "out" / "ground-station" / "security" / "identity.pem"));
  EXPECT_LE(secure.kib, insecure.kib + 512) << "with credentials " << secure.kib << " KiB, without "
                                            << insecure.kib << " KiB";
}

TEST_F(CompileMemory, AfterTheHandOverThePeakIsTheLargerOfTheTwoStepsNotTheLast) {
  // `eamos compile` becomes eamos-credentials by exec (the same process): Linux keeps the
  // larger resident size of its two images in ru_maxrss, which /usr/bin/time's %M and this
  // launcher report. Listing 2's credentials step is the larger, the 5,000 statements' compile.
  std::string listing2 = std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos";
  fs::path out = dir_ / "l2";
  Peak compiled = peak_of("compile -q " + listing2 + " -o " + out.string() + " --insecure");
  Peak secure = peak_of("compile -q " + listing2 + " -o " + out.string());
  ASSERT_EQ(secure.status, 0);
  std::ifstream in(out / "Drone1" / "mission.json");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::size_t at = text.find("\"mission_hash\":\"");
  ASSERT_NE(at, std::string::npos);
  std::string hash = text.substr(at + 16, 64);
  fs::path helper = fs::path(EAMOS_BINARY).parent_path() / "eamos-credentials";
  Peak credentials = peak_with(helper.string() + " --deploy-dir " + out.string() + " --mission-hash " + hash +
                               " -- Drone1 Drone2 Drone3");
  ASSERT_EQ(credentials.status, 0);
  EXPECT_GE(secure.kib, credentials.kib - 256) << "credentials alone " << credentials.kib << " KiB";
  EXPECT_GE(secure.kib, compiled.kib - 256) << "the compile alone " << compiled.kib << " KiB";
  Peak big_insecure = compile("--insecure");
  Peak big = compile("");
  EXPECT_GE(big.kib, big_insecure.kib - 256) << "the compile alone " << big_insecure.kib << " KiB";
}

TEST_F(CompileMemory, FiveThousandStatementsForTwentyDronesStayUnderTenAndAHalfMebibytes) {
  // Measured at 10,320-10,496 KiB on Debian 12: 5.3 MB of it the shared libraries' pages, the
  // rest the compile's data and code. 11.8 MB with libcrypto mapped in the same process (made the
  // credentials there), 14.9 MB with Cyclone DDS, iceoryx and civetweb loaded too.
  Peak p = compile("");
  ASSERT_EQ(p.status, 0);
  EXPECT_LE(p.kib, 10 * 1024 + 512) << "peak " << p.kib << " KiB";
}

std::string shell_output(const std::string& cmd) {
  std::string out;
  FILE* f = popen(("(" + cmd + ") 2>&1").c_str(), "r");
  if (!f) return out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, f)) out += buf;
  pclose(f);
  return out;
}

TEST(CompileCommand, LinksNeitherDdsNorTheWebServerNorOpenSsl) {
  // OpenSSL is eamos-credentials' (src/security), which a compile execs as its last step.
  std::string needed = shell_output(std::string("readelf -d ") + EAMOS_BINARY);
  ASSERT_NE(needed.find("(NEEDED)"), std::string::npos) << needed;
  for (const char* lib : {"libddsc", "libiceoryx", "libcivetweb", "libssl", "libcrypto"})
    EXPECT_EQ(needed.find(lib), std::string::npos) << lib << " in\n" << needed;
}

TEST(CompileCommand, ACompileWithoutEamosCredentialsInstalledSaysSoAndLeavesNoCredentials) {
  fs::path dir = fs::temp_directory_path() / ("eamos-alone-credentials-" + std::to_string(::getpid()));
  fs::create_directories(dir / "bin");
  fs::copy_file(EAMOS_BINARY, dir / "bin" / "eamos", fs::copy_options::overwrite_existing);
  std::string mission = std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos";
  fs::path out = dir / "out";
  // Another compilation's credentials in the folder: none of them may stay beside the new files.
  ASSERT_EQ(eamos_test::run_eamos("compile -q " + mission + " -o " + out.string()).status, 0);
  ASSERT_TRUE(fs::exists(out / "Drone1" / "security" / "identity.pem"));
  std::string said = shell_output((dir / "bin" / "eamos").string() + " compile -q " + mission + " -o " + out.string() +
                                  "; echo \"exit $?\"");
  EXPECT_NE(said.find("cannot start " + (dir / "libexec" / "eamos" / "eamos-credentials").string()), std::string::npos)
      << said;
  EXPECT_NE(said.find("reinstall eamos"), std::string::npos) << said;
  EXPECT_NE(said.find("exit 1"), std::string::npos) << said;
  EXPECT_EQ(said.find("compiled "), std::string::npos) << said;
  EXPECT_FALSE(fs::exists(out / "Drone1" / "security"));
  EXPECT_FALSE(fs::exists(out / "ground-station"));
  fs::remove_all(dir);
}

TEST(CompileCommand, ABadKeysFolderIsReportedThroughTheHandOverWithExitOne) {
  // eamos-credentials reads the CAs; its errors are the compile's, in the compile's words.
  fs::path dir = fs::temp_directory_path() / ("eamos-bad-keys-" + std::to_string(::getpid()));
  fs::create_directories(dir / "keys");
  std::fclose(std::fopen((dir / "keys" / "identity_ca.pem").c_str(), "w"));
  std::string mission = std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos";
  eamos_test::Output r = eamos_test::run_eamos("compile -q " + mission + " -o " + (dir / "out").string() +
                                               " --keys " + (dir / "keys").string());
  fs::remove_all(dir);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("eamos: error: cannot make the mission's DDS Security credentials: --keys " +
                       (dir / "keys").string() + " lacks identity_ca_key.pem, permissions_ca.pem, "
                       "permissions_ca_key.pem"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("compiled "), std::string::npos) << r.out;
}

TEST(CompileCommand, AFlyingCommandWithoutEamosFlyInstalledSaysSoAndFailsCleanly) {
  fs::path dir = fs::temp_directory_path() / ("eamos-alone-" + std::to_string(::getpid()));
  fs::create_directories(dir / "bin");
  fs::copy_file(EAMOS_BINARY, dir / "bin" / "eamos", fs::copy_options::overwrite_existing);
  std::string mission = std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos";
  std::string out = shell_output((dir / "bin" / "eamos").string() + " run -q " + mission + "; echo \"exit $?\"");
  fs::remove_all(dir);
  EXPECT_NE(out.find("cannot start " + (dir / "libexec" / "eamos" / "eamos-fly").string()), std::string::npos) << out;
  EXPECT_NE(out.find("reinstall eamos"), std::string::npos) << out;
  EXPECT_NE(out.find("exit 1"), std::string::npos) << out;
}

}  // namespace
