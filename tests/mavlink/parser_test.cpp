// The parser finds frames in any chunking, resynchronises on garbage, and counts what it
// rejects; a megabyte of noise neither crashes it nor yields a frame with a wrong checksum.
#include <gtest/gtest.h>

#include "helpers.h"
#include "mavlink/crc.h"
#include "mavlink/frame.h"
#include "mavlink/payloads.h"

namespace eamos::mavlink {
namespace {

using Bytes = std::vector<uint8_t>;

Bytes heartbeat_frame(uint8_t seq) {
  return encode_frame(pack(Heartbeat{.type = 2, .custom_mode = 7, .mavlink_version = 3}), seq,
                      1, 1);
}

Bytes ack_frame(uint8_t seq) {
  return encode_frame(pack(CommandAck{.command = 400, .result = 0}), seq, 1, 1);
}

Bytes join(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const Bytes& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

std::vector<uint8_t> seqs(const std::vector<Frame>& frames) {
  std::vector<uint8_t> out;
  for (const Frame& f : frames) out.push_back(f.seq);
  return out;
}

// The frame's checksum recomputed by the test's own CRC from what the parser reports.
bool checksum_holds(const Frame& f) {
  const MessageDef* def = find_message(f.message.id);
  if (!def) return false;
  Bytes covered{f.wire_length, f.incompat_flags, f.compat_flags, f.seq, f.sysid, f.compid,
                static_cast<uint8_t>(f.message.id), static_cast<uint8_t>(f.message.id >> 8),
                static_cast<uint8_t>(f.message.id >> 16)};
  covered.insert(covered.end(), f.message.payload.begin(),
                 f.message.payload.begin() + f.wire_length);
  covered.push_back(def->crc_extra);
  return test::bitwise_crc(covered) == f.checksum;
}

TEST(Parser, YieldsBackToBackFrames) {
  Parser p;
  auto frames = p.feed(join({heartbeat_frame(1), ack_frame(2), heartbeat_frame(3)}));
  EXPECT_EQ(seqs(frames), (std::vector<uint8_t>{1, 2, 3}));
  EXPECT_EQ(p.stats().frames, 3u);
}

TEST(Parser, ByteAtATimeGivesTheSameFrames) {
  Parser p;
  std::vector<Frame> frames;
  for (uint8_t b : join({heartbeat_frame(1), ack_frame(2)})) {
    auto got = p.feed(std::span(&b, 1));
    frames.insert(frames.end(), got.begin(), got.end());
  }
  EXPECT_EQ(seqs(frames), (std::vector<uint8_t>{1, 2}));
}

TEST(Parser, ResyncsAfterGarbageBeforeAndBetweenFrames) {
  Bytes garbage{0x00, 0xFD, 0x13, 0xFE, 0x55, 0xFD, 0x01};  // contains the magic byte twice
  Parser p;
  auto frames = p.feed(join({garbage, heartbeat_frame(1), garbage, ack_frame(2), garbage}));
  // The trailing garbage waits for more bytes; a later frame still comes out.
  auto later = p.feed(heartbeat_frame(3));
  frames.insert(frames.end(), later.begin(), later.end());
  EXPECT_EQ(seqs(frames), (std::vector<uint8_t>{1, 2, 3}));
  EXPECT_GT(p.stats().skipped_bytes, 0u);
}

TEST(Parser, ResyncsAfterAFrameCutInTheMiddle) {
  Bytes cut = heartbeat_frame(1);
  cut.resize(kHeaderLength);  // the next frame's bytes complete the cut one's claimed length
  Parser p;
  auto frames = p.feed(join({cut, ack_frame(2), heartbeat_frame(3)}));
  EXPECT_EQ(seqs(frames), (std::vector<uint8_t>{2, 3}));
  EXPECT_GE(p.stats().bad_crc, 1u);
}

TEST(Parser, RejectsAndCountsABadChecksum) {
  Bytes bad = heartbeat_frame(1);
  bad.back() ^= 0x01;
  Parser p;
  auto frames = p.feed(join({bad, ack_frame(2)}));
  EXPECT_EQ(seqs(frames), (std::vector<uint8_t>{2}));
  EXPECT_EQ(p.stats().bad_crc, 1u);
}

TEST(Parser, RejectsAPayloadFlippedInTransit) {
  Bytes bad = heartbeat_frame(1);
  bad[kHeaderLength] ^= 0x40;
  Parser p;
  EXPECT_TRUE(p.feed(bad).empty());
  EXPECT_EQ(p.stats().bad_crc, 1u);
}

TEST(Parser, SkipsAndCountsAnUnknownMessageId) {
  // A well-formed frame of message 12000, which the table does not know.
  Bytes unknown{0xFD, 2, 0, 0, 9, 1, 1, 0xE0, 0x2E, 0x00, 0x11, 0x22};
  uint16_t crc = test::bitwise_crc(Bytes(unknown.begin() + 1, unknown.end()));
  unknown.push_back(crc & 0xFF);
  unknown.push_back(crc >> 8);
  Parser p;
  auto frames = p.feed(join({unknown, heartbeat_frame(1)}));
  EXPECT_EQ(seqs(frames), (std::vector<uint8_t>{1}));
  EXPECT_EQ(p.stats().unknown_id, 1u);
}

TEST(Parser, DropsSignedFramesAsUnsupported) {
  Bytes hb = heartbeat_frame(1);
  Bytes signed_frame(hb.begin(), hb.end() - 2);
  signed_frame[2] = kIncompatSigned;
  Bytes covered(signed_frame.begin() + 1, signed_frame.end());
  covered.push_back(find_message(msg::HEARTBEAT)->crc_extra);
  uint16_t crc = test::bitwise_crc(covered);
  signed_frame.push_back(crc & 0xFF);
  signed_frame.push_back(crc >> 8);
  // link id, 6-byte timestamp, 6-byte signature: 0xFD inside must not start a frame.
  for (int i = 0; i < 13; ++i) signed_frame.push_back(i == 5 ? 0xFD : static_cast<uint8_t>(i));
  Parser p;
  auto frames = p.feed(join({signed_frame, ack_frame(2)}));
  EXPECT_EQ(seqs(frames), (std::vector<uint8_t>{2}));
  EXPECT_EQ(p.stats().unsupported, 1u);
  EXPECT_EQ(p.stats().bad_crc, 0u);
}

TEST(Parser, RejectsUnknownIncompatFlagsAtTheHeader) {
  Bytes odd = heartbeat_frame(1);
  odd[2] = 0x02;  // a flag this codec does not implement: the frame cannot be read safely
  Parser p;
  auto frames = p.feed(join({odd, ack_frame(2)}));
  EXPECT_EQ(seqs(frames), (std::vector<uint8_t>{2}));
  EXPECT_EQ(p.stats().unsupported, 1u);
}

TEST(Parser, TrimsExtensionBytesNewerThanTheTable) {
  // A sender with a newer common.xml appends a field to EXTENDED_SYS_STATE.
  Bytes longer{0xFD, 3, 0, 0, 5, 1, 1, 245, 0, 0, 0, 2, 9};
  Bytes covered(longer.begin() + 1, longer.end());
  covered.push_back(find_message(msg::EXTENDED_SYS_STATE)->crc_extra);
  uint16_t crc = test::bitwise_crc(covered);
  longer.push_back(crc & 0xFF);
  longer.push_back(crc >> 8);
  Parser p;
  auto frames = p.feed(longer);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].message.payload, (Bytes{0, 2}));
}

TEST(Parser, MegabyteOfNoiseYieldsOnlyValidFrames) {
  test::Random rng;
  Bytes noise(1 << 20);
  for (uint8_t& b : noise) b = rng.byte();
  // Real frames sprinkled in the noise must all come out.
  const size_t kPlanted = 64;
  for (size_t i = 0; i < kPlanted; ++i) {
    Bytes f = heartbeat_frame(static_cast<uint8_t>(i));
    std::copy(f.begin(), f.end(), noise.begin() + static_cast<std::ptrdiff_t>(i * 16000 + 77));
  }
  Parser p;
  std::vector<Frame> frames;
  for (size_t at = 0; at < noise.size();) {
    size_t chunk = std::min<size_t>(1 + rng.byte() % 200, noise.size() - at);
    auto got = p.feed(std::span(noise).subspan(at, chunk));
    frames.insert(frames.end(), got.begin(), got.end());
    at += chunk;
  }
  for (const Frame& f : frames) EXPECT_TRUE(checksum_holds(f));
  size_t planted_found = 0;
  for (const Frame& f : frames)
    if (f.message.id == msg::HEARTBEAT && f.sysid == 1 && f.compid == 1) ++planted_found;
  EXPECT_GE(planted_found, kPlanted);
}

}  // namespace
}  // namespace eamos::mavlink
