#include "diag/log.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

namespace {

using namespace eamos::diag;

// Collects the lines logged while it lives and puts the level and sink back afterwards.
struct CapturedLog {
  std::vector<std::string> lines;
  LogLevel saved_level = log_level();
  CapturedLog() {
    set_log_sink([this](std::string_view line) { lines.emplace_back(line); });
  }
  ~CapturedLog() {
    set_log_sink({});
    set_log_level(saved_level);
  }
};

TEST(Log, ALineNamesTheProgramComponentSubjectAndLevel) {
  EXPECT_EQ(format_log_line(LogLevel::warning, "dex", "Drone2", "late trigger"),
            "eamos dex Drone2: warning: late trigger");
  EXPECT_EQ(format_log_line(LogLevel::error, "transport", "", "dropped a lifecycle sample"),
            "eamos transport: error: dropped a lifecycle sample");
}

TEST(Log, ALevelShowsItselfAndEveryMoreSevereOneOnly) {
  CapturedLog log;
  set_log_level(LogLevel::warning);
  Logger l{"mavlink", "Drone1"};
  l.error("e");
  l.warning("w");
  l.info("i");
  l.debug("d");
  EXPECT_EQ(log.lines, (std::vector<std::string>{"eamos mavlink Drone1: error: e", "eamos mavlink Drone1: warning: w"}));
  EXPECT_FALSE(log_enabled(LogLevel::info));
  EXPECT_TRUE(log_enabled(LogLevel::error));
}

TEST(Log, DebugShowsEverythingAndErrorOnlyErrors) {
  CapturedLog log;
  Logger l{"mid", ""};
  set_log_level(LogLevel::debug);
  l.debug("d");
  set_log_level(LogLevel::error);
  l.warning("w");
  l.error("e");
  EXPECT_EQ(log.lines, (std::vector<std::string>{"eamos mid: debug: d", "eamos mid: error: e"}));
}

TEST(Log, WithoutASinkALineGoesToStandardErrorWithItsNewline) {
  LogLevel saved = log_level();
  set_log_level(LogLevel::info);
  testing::internal::CaptureStderr();
  Logger{"dex", "Drone3"}.info("landed");
  std::string err = testing::internal::GetCapturedStderr();
  set_log_level(saved);
  EXPECT_EQ(err, "eamos dex Drone3: info: landed\n");
}

TEST(Log, ASinkThatThrowsLosesOnlyThatLine) {
  CapturedLog log;
  set_log_level(LogLevel::info);
  set_log_sink([](std::string_view) { throw std::runtime_error("disk full"); });
  testing::internal::CaptureStderr();
  EXPECT_NO_THROW((Logger{"dex", ""}.info("x")));
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "eamos: a log message was lost\n");
}

TEST(LogLevelNames, ParseEveryNameAndRefuseOthers) {
  for (LogLevel l : {LogLevel::error, LogLevel::warning, LogLevel::info, LogLevel::debug})
    EXPECT_EQ(parse_log_level(log_level_name(l)), l);
  EXPECT_EQ(parse_log_level("WARNING"), std::nullopt);
  EXPECT_EQ(parse_log_level("verbose"), std::nullopt);
  EXPECT_EQ(parse_log_level(""), std::nullopt);
}

TEST(LogLevelNames, TheEnvironmentVariableSetsTheDefaultAndABadValueIsIgnored) {
  setenv(kLogLevelVariable, "debug", 1);
  EXPECT_EQ(default_log_level(), LogLevel::debug);
  setenv(kLogLevelVariable, "loud", 1);
  EXPECT_EQ(default_log_level(), LogLevel::info);
  unsetenv(kLogLevelVariable);
  EXPECT_EQ(default_log_level(), LogLevel::info);
}

}  // namespace
