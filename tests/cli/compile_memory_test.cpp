// The peak resident memory of the whole `eamos compile` process (docs/performance.md, "Against
// the paper"): bytes, not time, so the bounds hold on a loaded machine.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;

struct Peak {
  long kib = -1;
  int status = -1;
};

/// `eamos args` through the small launcher, so that its peak is eamos's own.
Peak peak_of(const std::string& args) {
  std::string cmd = std::string(EAMOS_PEAK_RSS) + " " + EAMOS_BINARY + " " + args;
  Peak p;
  FILE* f = popen(cmd.c_str(), "r");
  if (!f) return p;
  if (std::fscanf(f, "peak_kib %ld status %d", &p.kib, &p.status) != 2) p.kib = -1;
  pclose(f);
  return p;
}

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

TEST_F(CompileMemory, FiveThousandStatementsForTwentyDronesStayUnderSixteenMegabytes) {
  // Measured at 14.6-15.1 MB on Debian 12 (8.4 MB of it shared libraries before main).
  Peak p = compile("");
  ASSERT_EQ(p.status, 0);
  EXPECT_LE(p.kib, 16 * 1024) << "peak " << p.kib << " KiB";
}

}  // namespace
