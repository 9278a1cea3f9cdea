// The MavlinkDrone's parts that stand alone, on virtual time: the autopilot's texts, the
// vehicle's clock and the count of mode commands in flight.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mavlink/enums.h"
#include "mavlink_adapter/autopilot_texts.h"
#include "mavlink_adapter/mode_commands.h"
#include "mavlink_adapter/vehicle_clock.h"

namespace eamos::mavlink_adapter {
namespace {

namespace ml = eamos::mavlink;

ml::Statustext text(const std::string& s, uint8_t severity = 4, uint16_t id = 0, uint8_t chunk = 0) {
  ml::Statustext t;
  t.severity = severity;
  t.text = s;
  t.id = id;
  t.chunk_seq = chunk;
  t.full = s.size() == 50;  // as unpack_statustext reads it
  return t;
}

using Lines = std::vector<std::string>;

TEST(AutopilotTexts, AChunkedTextIsTracedWholeOnceItsShortLastChunkCame) {
  AutopilotTexts texts;
  const std::string first(50, 'a');
  EXPECT_EQ(texts.add(text(first, 3, 7), 1.0, "ArduPilot"), Lines{});
  EXPECT_EQ(texts.add(text("end", 3, 7, 1), 1.1, "ArduPilot"), Lines{"ArduPilot error: " + first + "end"});
}

// PX4 numbers its texts from 0, which MAVLink keeps for a text of one chunk: its first text
// after start, when longer than 50 characters, still comes whole (read as two, it said
// "Arming denied: Resolve system health failures firs" and then "t").
TEST(AutopilotTexts, APx4TextOfTwoChunksUnderIdZeroIsTracedWhole) {
  AutopilotTexts texts;
  EXPECT_EQ(texts.add(text("Arming denied: Resolve system health failures firs", 2, 0), 1.0, "PX4"), Lines{});
  EXPECT_EQ(texts.add(text("t", 2, 0, 1), 1.0, "PX4"),
            Lines{"PX4 critical: Arming denied: Resolve system health failures first"});
  EXPECT_EQ(texts.says(0.0, "PX4"), "; PX4 says: Arming denied: Resolve system health failures first");
}

// A text of exactly 50 characters fills its only chunk, and PX4 sends no empty one after
// it: the next text ends it, or its wait does.
TEST(AutopilotTexts, ATextThatFillsItsOnlyChunkIsTracedByTheNextTextOrAfterItsWait) {
  AutopilotTexts texts;
  const std::string fifty(50, 'x');
  EXPECT_EQ(texts.add(text(fifty, 4, 5), 1.0, "PX4"), Lines{});
  EXPECT_EQ(texts.add(text("Takeoff detected", 6, 6), 1.2, "PX4"),
            (Lines{"PX4 warning: " + fifty, "PX4 info: Takeoff detected"}));
  EXPECT_EQ(texts.add(text(fifty, 4, 7), 2.0, "PX4"), Lines{});
  EXPECT_EQ(texts.says(2.0, "PX4"), "; PX4 says: " + fifty);  // a refusal quotes it meanwhile
  EXPECT_EQ(texts.flush(2.5, "PX4"), Lines{});
  EXPECT_EQ(texts.flush(3.0, "PX4"), Lines{"PX4 warning: " + fifty});
  EXPECT_EQ(texts.flush(9.0, "PX4"), Lines{});
}

// A chunk may end on the blank between two words: the text keeps it.
TEST(AutopilotTexts, ABlankAtTheEndOfAChunkStaysBetweenItsWords) {
  AutopilotTexts texts;
  const std::string chunk = "Preflight Fail: the vehicle is too far from its   ";  // 50
  ASSERT_EQ(chunk.size(), 50u);
  EXPECT_EQ(texts.add(text(chunk, 4, 9), 1.0, "PX4"), Lines{});
  EXPECT_EQ(texts.add(text("home", 4, 9, 1), 1.0, "PX4"), Lines{"PX4 warning: " + chunk + "home"});
}

// A sender that never ends a text (every chunk full) cannot grow it without bound.
TEST(AutopilotTexts, ATextThatNeverEndsIsCutAtEightChunks) {
  AutopilotTexts texts;
  Lines said;
  for (int i = 0; i < 20; ++i)
    for (const std::string& s : texts.add(text(std::string(50, 'z'), 4, 3, static_cast<uint8_t>(i + 1)), 1.0, "X"))
      said.push_back(s);
  ASSERT_EQ(said.size(), 2u);
  EXPECT_EQ(said[0], "X warning: " + std::string(400, 'z'));
}

TEST(AutopilotTexts, ARefusalQuotesOnlyWarningsAndWorseSaidSinceItStarted) {
  AutopilotTexts texts;
  texts.add(text("PreArm: before", 4), 1.0, "ArduPilot");
  texts.add(text("just information", 6), 2.0, "ArduPilot");
  texts.add(text("Arm: LAND mode not armable", 4), 2.5, "ArduPilot");
  texts.add(text("Arm: LAND mode not armable", 4), 2.6, "ArduPilot");
  EXPECT_EQ(texts.says(2.0, "ArduPilot"), "; ArduPilot says: Arm: LAND mode not armable");
  EXPECT_EQ(texts.says(3.0, "ArduPilot"), "");
}

TEST(VehicleClock, AVehicleAtHalfTheMissionsPaceStretchesEveryWaitTwiceAndSaysSoOnce) {
  mid::EventLoop loop;
  std::vector<std::string> notes;
  VehicleClock clock(loop, [&](const std::string& n) { notes.push_back(n); });
  for (int i = 0; i <= 40; ++i) {
    loop.run_until(i * 0.1);
    clock.on_report(static_cast<uint32_t>(i * 50));  // 50 ms of the vehicle per 100 ms of ours
  }
  EXPECT_NEAR(clock.rate(), 0.5, 1e-9);
  EXPECT_NEAR(clock.mission_s(3.0), 6.0, 1e-9);
  EXPECT_EQ(notes.size(), 1u);
}

TEST(VehicleClock, AVehicleClockAheadOfOursNeverShortensAWait) {
  mid::EventLoop loop;
  VehicleClock clock(loop, [](const std::string&) {});
  for (int i = 0; i <= 40; ++i) {
    loop.run_until(i * 0.1);
    clock.on_report(static_cast<uint32_t>(i * 200));
  }
  EXPECT_NEAR(clock.rate(), 2.0, 1e-9);
  EXPECT_DOUBLE_EQ(clock.mission_s(3.0), 3.0);
}

TEST(ModeCommands, AModeChangeCountsAsPendingUntilItsAnswerCame) {
  mid::EventLoop loop;
  CommandSender sender(loop, [](const ml::Message&) {});
  ModeCommands modes(sender);
  ml::CommandLong c;
  c.command = ml::cmd::DO_SET_MODE;
  bool answered = false;
  modes.send(c, [&](const CommandResult& r) { answered = r.accepted; });
  EXPECT_TRUE(modes.pending());
  ml::CommandAck ack;
  ack.command = ml::cmd::DO_SET_MODE;
  ack.result = 0;  // MAV_RESULT_ACCEPTED
  sender.on_ack(ack);
  loop.run_until_idle();
  EXPECT_TRUE(answered);
  EXPECT_FALSE(modes.pending());
}

}  // namespace
}  // namespace eamos::mavlink_adapter
