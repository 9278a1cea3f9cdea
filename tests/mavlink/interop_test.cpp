// Frames written by an independent MAVLink implementation: the byte vectors below are the
// HEARTBEAT and the truncated COMMAND_LONG of rust-mavlink's v2 tests. Our codec must decode
// them to the same values and, given those values, write the same bytes, CRC included.
#include <gtest/gtest.h>

#include "mavlink/frame.h"
#include "mavlink/payloads.h"

namespace eamos::mavlink {
namespace {

// seq 239, system 1, component 2; custom_mode 5, QUADROTOR, ARDUPILOTMEGA, base_mode 0x59,
// STANDBY, version 3.
const std::vector<uint8_t> kHeartbeat{0xFD, 0x09, 0x00, 0x00, 0xEF, 0x01, 0x02, 0x00, 0x00,
                                      0x00, 0x05, 0x00, 0x00, 0x00, 0x02, 0x03, 0x59, 0x03,
                                      0x03, 0x2E, 0x73};

// seq 0, system 0, component 50; SET_MESSAGE_INTERVAL (511) for message 115 every 5000 µs,
// payload truncated after `command` (target and confirmation are zero).
const std::vector<uint8_t> kCommandLong{
    253, 30, 0, 0, 0, 0, 50, 76, 0, 0, 0, 0, 230, 66, 0, 64, 156, 69, 0, 0, 0, 0, 0, 0, 0, 0,
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 255, 1, 188, 195};

TEST(Interop, DecodesAHeartbeatWrittenByAnotherImplementation) {
  Parser parser;
  auto frames = parser.feed(kHeartbeat);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].seq, 239);
  EXPECT_EQ(frames[0].sysid, 1);
  EXPECT_EQ(frames[0].compid, 2);
  auto hb = unpack_heartbeat(frames[0].message);
  ASSERT_TRUE(hb);
  EXPECT_EQ(hb->custom_mode, 5u);
  EXPECT_EQ(hb->type, 2);
  EXPECT_EQ(hb->autopilot, 3);
  EXPECT_EQ(hb->base_mode, 0x59);
  EXPECT_EQ(hb->system_status, 3);
  EXPECT_EQ(hb->mavlink_version, 3);
}

TEST(Interop, WritesTheSameHeartbeatBytes) {
  Heartbeat hb{.type = 2, .autopilot = 3, .base_mode = 0x59, .custom_mode = 5,
               .system_status = 3, .mavlink_version = 3};
  Encoder enc{.sysid = 1, .compid = 2, .next_seq = 239};
  EXPECT_EQ(enc.encode(pack(hb)), kHeartbeat);
}

TEST(Interop, TruncatedCommandLongDecodesAndReencodesIdentically) {
  Parser parser;
  auto frames = parser.feed(kCommandLong);
  ASSERT_EQ(frames.size(), 1u);
  auto c = unpack_command_long(frames[0].message);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->command, 511);
  EXPECT_FLOAT_EQ(c->param[0], 115.0f);
  EXPECT_FLOAT_EQ(c->param[1], 5000.0f);
  EXPECT_EQ(c->target_system, 0);
  EXPECT_EQ(encode_frame(frames[0].message, 0, 0, 50), kCommandLong);
}

}  // namespace
}  // namespace eamos::mavlink
