// Encoding: exact bytes of a hand-checked HEARTBEAT frame, v2 payload truncation, and the
// per-sender sequence number.
#include <gtest/gtest.h>

#include "helpers.h"
#include "mavlink/frame.h"
#include "mavlink/payloads.h"

namespace eamos::mavlink {
namespace {

TEST(Encode, HeartbeatFrameHasTheExpectedBytes) {
  Heartbeat hb{.type = 2, .autopilot = 12, .base_mode = 0x81, .custom_mode = 0x04030201,
               .system_status = 4, .mavlink_version = 3};
  Encoder enc{.sysid = 42, .compid = 191, .next_seq = 7};

  std::vector<uint8_t> want{0xFD, 9, 0, 0, 7, 42, 191, 0, 0, 0};  // header, msgid 0
  // Payload in wire order: custom_mode (uint32 LE) first, then the five uint8 fields.
  for (uint8_t b : {0x01, 0x02, 0x03, 0x04, 2, 12, 0x81, 4, 3}) want.push_back(b);
  std::vector<uint8_t> checked(want.begin() + 1, want.end());
  checked.push_back(50);  // HEARTBEAT's CRC_EXTRA
  uint16_t crc = test::bitwise_crc(checked);
  want.push_back(crc & 0xFF);
  want.push_back(crc >> 8);

  EXPECT_EQ(enc.encode(pack(hb)), want);
}

TEST(Encode, DropsTrailingZeroBytes) {
  Heartbeat hb{.type = 2, .custom_mode = 0, .system_status = 0, .mavlink_version = 0};
  auto frame = encode_frame(pack(hb), 0, 1, 1);
  ASSERT_GE(frame.size(), 2u);
  EXPECT_EQ(frame[1], 5);  // custom_mode (4 zero bytes, kept: not trailing) + type
  EXPECT_EQ(frame.size(), kHeaderLength + 5 + kCrcLength);
}

TEST(Encode, AllZeroPayloadKeepsOneByte) {
  auto frame = encode_frame(pack(ExtendedSysState{}), 0, 1, 1);
  EXPECT_EQ(frame[1], 1);
  EXPECT_EQ(frame[kHeaderLength], 0);
}

TEST(Encode, ExtensionFieldsLeftZeroAreNotSent) {
  auto frame = encode_frame(pack(CommandAck{.command = 400, .result = 4}), 0, 1, 1);
  EXPECT_EQ(frame[1], 3);
}

TEST(Encode, TwentyFourBitMessageIdIsLittleEndian) {
  auto frame = encode_frame(pack(ExtendedSysState{.landed_state = 1}), 0, 1, 1);
  EXPECT_EQ(frame[7], 245);
  EXPECT_EQ(frame[8], 0);
  EXPECT_EQ(frame[9], 0);
}

TEST(Encode, UnknownMessageIdGivesNoFrame) {
  EXPECT_TRUE(encode_frame(Message{999999, {1, 2}}, 0, 1, 1).empty());
}

TEST(Encoder, SequenceWrapsFrom255To0) {
  Encoder enc{.sysid = 1, .compid = 1, .next_seq = 254};
  Message hb = pack(Heartbeat{});
  EXPECT_EQ(enc.encode(hb)[4], 254);
  EXPECT_EQ(enc.encode(hb)[4], 255);
  EXPECT_EQ(enc.encode(hb)[4], 0);
  EXPECT_EQ(enc.encode(hb)[4], 1);
}

TEST(Decode, TruncatedPayloadIsZeroFilled) {
  Parser parser;
  auto frames = parser.feed(encode_frame(pack(CommandAck{.command = 400, .result = 4}), 0, 1, 1));
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].wire_length, 3);
  EXPECT_EQ(frames[0].message.payload.size(), 10u);
  auto ack = unpack_command_ack(frames[0].message);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->command, 400);
  EXPECT_EQ(ack->result, 4);
  EXPECT_EQ(ack->result_param2, 0);
}

TEST(Decode, HeaderFieldsComeBack) {
  Encoder enc{.sysid = 3, .compid = 1, .next_seq = 200};
  Parser parser;
  auto frames = parser.feed(enc.encode(pack(Heartbeat{})));
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].seq, 200);
  EXPECT_EQ(frames[0].sysid, 3);
  EXPECT_EQ(frames[0].compid, 1);
  EXPECT_EQ(frames[0].message.id, msg::HEARTBEAT);
}

}  // namespace
}  // namespace eamos::mavlink
