// COMMAND_LONG delivery on virtual time: resends count the confirmation field up, an ACK
// ends the command, silence ends it with a message, one command per id is in flight.
#include <gtest/gtest.h>

#include "mavlink/enums.h"
#include "mavlink_adapter/command_sender.h"

namespace eamos::mavlink_adapter {
namespace {

namespace ml = eamos::mavlink;

struct Fixture {
  mid::EventLoop loop;
  std::vector<ml::CommandLong> sent;
  CommandSender sender{loop, [this](const ml::Message& m) { sent.push_back(*ml::unpack_command_long(m)); },
                       CommandOptions{1.0, 2, 10.0}};
};

ml::CommandLong arm() {
  ml::CommandLong c;
  c.command = ml::cmd::COMPONENT_ARM_DISARM;
  c.param[0] = 1;
  return c;
}

TEST(CommandSender, ResendsWithTheConfirmationCountedUpThenGivesUp) {
  Fixture f;
  std::optional<CommandResult> result;
  f.sender.send(arm(), [&](const CommandResult& r) { result = r; });
  f.loop.run_until_idle();
  ASSERT_EQ(f.sent.size(), 3u);
  EXPECT_EQ(f.sent[0].confirmation, 0);
  EXPECT_EQ(f.sent[1].confirmation, 1);
  EXPECT_EQ(f.sent[2].confirmation, 2);
  ASSERT_TRUE(result);
  EXPECT_FALSE(result->accepted);
  EXPECT_EQ(result->error, "MAV_CMD_COMPONENT_ARM_DISARM: no COMMAND_ACK after 3 tries (1.0 s each)");
  EXPECT_DOUBLE_EQ(f.loop.now(), 3.0);
}

TEST(CommandSender, RefusalCarriesTheResultInWords) {
  Fixture f;
  std::optional<CommandResult> result;
  f.sender.send(arm(), [&](const CommandResult& r) { result = r; });
  f.sender.on_ack({ml::cmd::COMPONENT_ARM_DISARM, ml::result::DENIED});
  ASSERT_TRUE(result);
  EXPECT_FALSE(result->accepted);
  EXPECT_EQ(result->error, "MAV_CMD_COMPONENT_ARM_DISARM: MAV_RESULT_DENIED (denied by the autopilot)");
  f.loop.run_until_idle();
  EXPECT_EQ(f.sent.size(), 1u);  // no resend after the answer
}

TEST(CommandSender, InProgressWaitsForTheFinalAck) {
  Fixture f;
  std::optional<CommandResult> result;
  f.sender.send(arm(), [&](const CommandResult& r) { result = r; });
  f.sender.on_ack({ml::cmd::COMPONENT_ARM_DISARM, ml::result::IN_PROGRESS});
  f.loop.run_until(5.0);
  EXPECT_FALSE(result);
  EXPECT_EQ(f.sent.size(), 1u);
  f.sender.on_ack({ml::cmd::COMPONENT_ARM_DISARM, ml::result::ACCEPTED});
  ASSERT_TRUE(result);
  EXPECT_TRUE(result->accepted);
}

TEST(CommandSender, SameCommandIdWaitsForThePreviousAck) {
  Fixture f;
  int done = 0;
  ml::CommandLong a = arm(), b = arm();
  b.param[0] = 0;
  f.sender.send(a, [&](const CommandResult&) { ++done; });
  f.sender.send(b, [&](const CommandResult&) { ++done; });
  ASSERT_EQ(f.sent.size(), 1u);
  f.sender.on_ack({ml::cmd::COMPONENT_ARM_DISARM, ml::result::ACCEPTED});
  ASSERT_EQ(f.sent.size(), 2u);
  EXPECT_EQ(f.sent[1].param[0], 0.0f);
  f.sender.on_ack({ml::cmd::COMPONENT_ARM_DISARM, ml::result::ACCEPTED});
  EXPECT_EQ(done, 2);
  EXPECT_EQ(f.sender.pending(), 0u);
}

// A correction that an orbit's end made obsolete must not reach the vehicle after the mode
// switch that ended it: its resend is dropped, and the next command of its id goes out.
TEST(CommandSender, ACommandNoLongerWantedIsNotSentAgain) {
  Fixture f;
  bool wanted = true;
  std::optional<CommandResult> result;
  int next_done = 0;
  f.sender.send(arm(), [&](const CommandResult& r) { result = r; }, [&] { return wanted; });
  f.sender.send(arm(), [&](const CommandResult&) { ++next_done; });
  wanted = false;
  f.loop.run_until(1.5);
  ASSERT_TRUE(result);
  EXPECT_FALSE(result->accepted);
  EXPECT_FALSE(result->answered);
  EXPECT_EQ(result->error, "MAV_CMD_COMPONENT_ARM_DISARM: no COMMAND_ACK, and not sent again: no longer wanted");
  ASSERT_EQ(f.sent.size(), 2u);  // the first once, then the next one: no resend between
  EXPECT_EQ(f.sent[1].confirmation, 0);
  f.sender.on_ack({ml::cmd::COMPONENT_ARM_DISARM, ml::result::ACCEPTED});
  EXPECT_EQ(next_done, 1);
}

// An ARM queued behind another of its id whose action ended meanwhile is never sent: it
// would arm a vehicle left down and disarmed in its failsafe.
TEST(CommandSender, AQueuedCommandNoLongerWantedIsNotSentAtAll) {
  Fixture f;
  bool wanted = true;
  std::vector<std::string> results;
  ml::CommandLong disarm = arm();
  disarm.param[0] = 0;
  f.sender.send(disarm, [&](const CommandResult& r) { results.push_back(r.error); });
  f.sender.send(arm(), [&](const CommandResult& r) { results.push_back(r.error); }, [&] { return wanted; });
  f.sender.send(disarm, [&](const CommandResult& r) { results.push_back(r.error); });
  ASSERT_EQ(f.sent.size(), 1u);
  wanted = false;
  f.sender.on_ack({ml::cmd::COMPONENT_ARM_DISARM, ml::result::ACCEPTED});
  ASSERT_EQ(f.sent.size(), 2u);  // the second DISARM, not the ARM
  EXPECT_EQ(f.sent[1].param[0], 0.0f);
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[0], "");
  EXPECT_EQ(results[1], "MAV_CMD_COMPONENT_ARM_DISARM: not sent: no longer wanted");
  f.sender.on_ack({ml::cmd::COMPONENT_ARM_DISARM, ml::result::ACCEPTED});
  EXPECT_EQ(results.size(), 3u);
  EXPECT_EQ(f.sender.pending(), 0u);
}

TEST(CommandSender, FailAllEndsEveryQueuedCommand) {
  Fixture f;
  std::vector<std::string> errors;
  f.sender.send(arm(), [&](const CommandResult& r) { errors.push_back(r.error); });
  ml::CommandLong land;
  land.command = ml::cmd::NAV_LAND;
  f.sender.send(land, [&](const CommandResult& r) { errors.push_back(r.error); });
  f.sender.fail_all("link lost");
  EXPECT_EQ(errors.size(), 2u);
  EXPECT_EQ(f.sender.pending(), 0u);
  f.loop.run_until_idle();
  EXPECT_EQ(f.sent.size(), 2u);  // the timers went with them
}

}  // namespace
}  // namespace eamos::mavlink_adapter
