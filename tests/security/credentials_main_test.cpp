// eamos-credentials, the last step of `eamos compile`, run as a compile runs it and with
// arguments no compile gives: each wrong one is reported and nothing is written.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;

using Result = eamos_test::Output;

Result credentials(const std::string& args) { return eamos_test::run_program(EAMOS_CREDENTIALS, args); }

class EamosCredentials : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eamos-credentials-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_ / "D0");
    fs::create_directories(dir_ / "D1");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  const std::string hash_ = "50e175b6bcc7a6bafaf62917e1de2c7ca200ebb39118ae6688c60aa51255ece8";
};

TEST_F(EamosCredentials, EveryWrongArgumentIsReportedAndNothingIsWritten) {
  Result r = credentials("--deploy-dir " + dir_.string() + " --mission-hash NOTHEX --valid-days 0 --colour never -- D0 ../D1");
  EXPECT_EQ(r.status, 1) << r.out;
  for (const char* says : {"--mission-hash needs the mission hash in lower-case hex",
                           "'--valid-days 0' is not an option of eamos-credentials",
                           "'--colour never' is not an option of eamos-credentials", "'../D1' is not a drone name",
                           "usage: eamos-credentials"})
    EXPECT_NE(r.out.find(says), std::string::npos) << says << " in\n" << r.out;
  EXPECT_FALSE(fs::exists(dir_ / "D0" / "security"));
  EXPECT_FALSE(fs::exists(dir_ / "ground-station"));
}

TEST_F(EamosCredentials, WithoutArgumentsItSaysWhatItNeeds) {
  Result r = credentials("");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("--deploy-dir is missing"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("no drones after --"), std::string::npos) << r.out;
  Result dangling = credentials("--deploy-dir");
  EXPECT_EQ(dangling.status, 1);
  EXPECT_NE(dangling.out.find("--deploy-dir needs a value"), std::string::npos) << dangling.out;
}

TEST_F(EamosCredentials, AsACompileRunsItEachParticipantGetsItsSixFilesAndTheLastLinesFollow) {
  Result r = credentials("--deploy-dir " + dir_.string() + " --mission-hash " + hash_ +
                         " --valid-days 2 --color never --done 'compiled it' -- D0 D1");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(r.out, "compiled it");
  for (const char* who : {"D0", "D1", "ground-station"}) {
    fs::path folder = dir_ / who / "security";
    for (const char* f : {"identity_ca.pem", "permissions_ca.pem", "governance.p7s", "identity.pem", "identity_key.pem",
                          "permissions.p7s"})
      EXPECT_GT(fs::file_size(folder / f), 0u) << who << "/" << f;
    struct stat st{};
    ASSERT_EQ(::stat((folder / "identity_key.pem").c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0600u) << who;
    ASSERT_EQ(::stat(folder.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0700u) << who;
  }
}

TEST_F(EamosCredentials, AFolderItCannotMakeIsReportedAsTheCompilesError) {
  fs::path file = dir_ / "not-a-folder";
  std::fclose(std::fopen(file.c_str(), "w"));
  Result r = credentials("--deploy-dir " + file.string() + " --mission-hash " + hash_ + " -- D0");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("eamos: error: cannot make the mission's DDS Security credentials: cannot create '" +
                       (file / "D0" / "security").string() + "'"),
            std::string::npos)
      << r.out;
}

}  // namespace
