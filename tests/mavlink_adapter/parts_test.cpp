// The MavlinkDrone's parts that stand alone, on virtual time: the autopilot's texts, the
// vehicle's clock and the count of mode commands in flight.
#include <gtest/gtest.h>

#include <string>

#include "mavlink/enums.h"
#include "mavlink_adapter/autopilot_texts.h"
#include "mavlink_adapter/mode_commands.h"
#include "mavlink_adapter/vehicle_clock.h"

namespace eamos::mavlink_adapter {
namespace {

namespace ml = eamos::mavlink;

ml::Statustext text(const std::string& s, uint8_t severity = 4, uint16_t id = 0) {
  ml::Statustext t;
  t.severity = severity;
  t.text = s;
  t.id = id;
  return t;
}

TEST(AutopilotTexts, AChunkedTextIsTracedWholeOnceItsShortLastChunkCame) {
  AutopilotTexts texts;
  const std::string first(50, 'a');
  EXPECT_FALSE(texts.add(text(first, 3, 7), 1.0, "ArduPilot"));
  std::optional<std::string> whole = texts.add(text("end", 3, 7), 1.1, "ArduPilot");
  ASSERT_TRUE(whole);
  EXPECT_EQ(*whole, "ArduPilot error: " + first + "end");
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
