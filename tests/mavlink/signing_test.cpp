// MAVLink 2 signing: the signature of a known frame matches one computed independently
// (Python's hashlib over the bytes the spec names, with its own X.25 CRC); frames we sign are
// accepted by a verifier with the key and refused with another, tampered, replayed, too old
// or (once required) unsigned; a parser with a key survives noise and truncated frames.
#include <gtest/gtest.h>

#include <random>

#include "mavlink/frame.h"
#include "mavlink/messages.h"
#include "mavlink/payloads.h"
#include "mavlink/signing.h"

namespace eamos::mavlink {
namespace {

using Bytes = std::vector<uint8_t>;

Bytes from_hex(const std::string& hex) {
  Bytes out;
  for (size_t i = 0; i + 1 < hex.size(); i += 2) out.push_back(static_cast<uint8_t>(std::stoi(hex.substr(i, 2), nullptr, 16)));
  return out;
}

SigningKey counting_key() {
  SigningKey k;
  for (int i = 0; i < 32; ++i) k.bytes[i] = static_cast<uint8_t>(i);
  return k;
}

// HEARTBEAT {custom_mode 0, type 2, autopilot 3, base_mode 0, system_status 4, version 3},
// seq 0, system 1, component 1, signed flag set; link id 1, timestamp 0x123456789A; key
// 00 01 … 1f. Computed with Python 3: hashlib.sha256(key + frame + link + ts48le)[:6].
const char* kSignedHeartbeat = "fd090100000101000000000000000203000403ad2f019a785634120032af870cdbe4";

Message heartbeat_message() {
  Message m{msg::HEARTBEAT, {0, 0, 0, 0, 2, 3, 0, 4, 3}};
  return m;
}

TEST(MavlinkSigning, SignatureOfAKnownFrameMatchesAnIndependentComputation) {
  Bytes expected = from_hex(kSignedHeartbeat);
  Bytes frame(expected.begin(), expected.end() - kSignatureLength);
  std::array<uint8_t, 6> sig = signature_of(counting_key(), frame, 1, 0x123456789Aull);
  EXPECT_EQ(Bytes(sig.begin(), sig.end()), Bytes(expected.end() - 6, expected.end()));
}

TEST(MavlinkSigning, SignerSetsTheFlagRecomputesTheCrcAndAppendsTheTrailer) {
  Bytes expected = from_hex(kSignedHeartbeat);
  Signer signer(counting_key(), 1);
  Bytes signed_frame = signer.sign(encode_frame(heartbeat_message(), 0, 1, 1));
  ASSERT_EQ(signed_frame.size(), expected.size());
  // Header, payload and CRC (over the header with the signed flag) as computed in Python.
  EXPECT_EQ(Bytes(signed_frame.begin(), signed_frame.begin() + 21), Bytes(expected.begin(), expected.begin() + 21));
  EXPECT_EQ(signed_frame[21], 1);  // link id
  uint64_t t = 0;
  for (int i = 0; i < 6; ++i) t |= uint64_t(signed_frame[22 + i]) << (8 * i);
  EXPECT_NEAR(static_cast<double>(t), static_cast<double>(signing_time_now()), 100000.0);  // within 1 s of now
  std::array<uint8_t, 6> sig = signature_of(counting_key(), std::span(signed_frame).first(21), 1, t);
  EXPECT_EQ(Bytes(sig.begin(), sig.end()), Bytes(signed_frame.end() - 6, signed_frame.end()));
}

TEST(MavlinkSigning, TimestampsOfOneSignerOnlyGrow) {
  Signer signer(counting_key(), 0);
  uint64_t last = 0;
  for (int i = 0; i < 100; ++i) {
    Bytes f = signer.sign(encode_frame(heartbeat_message(), 0, 1, 1));
    uint64_t t = 0;
    for (int b = 0; b < 6; ++b) t |= uint64_t(f[f.size() - 12 + b]) << (8 * b);
    EXPECT_GT(t, last);
    last = t;
  }
}

TEST(MavlinkSigning, VerifierAcceptsGoodFramesAndRefusesEverythingElse) {
  Signer signer(counting_key(), 2);
  Verifier verifier(counting_key());
  Bytes first = signer.sign(encode_frame(heartbeat_message(), 0, 1, 1));
  Bytes second = signer.sign(encode_frame(heartbeat_message(), 1, 1, 1));
  EXPECT_EQ(verifier.check(first), SignatureVerdict::good);
  EXPECT_EQ(verifier.check(second), SignatureVerdict::good);
  EXPECT_EQ(verifier.check(first), SignatureVerdict::replayed);  // the same frame again
  Bytes tampered = signer.sign(encode_frame(heartbeat_message(), 2, 1, 1));
  tampered[14] ^= 0x01;  // a payload byte
  EXPECT_EQ(verifier.check(tampered), SignatureVerdict::bad_signature);
  SigningKey other = counting_key();
  other.bytes[0] = 0xFF;
  Signer stranger(other, 2);
  EXPECT_EQ(verifier.check(stranger.sign(encode_frame(heartbeat_message(), 3, 1, 1))), SignatureVerdict::bad_signature);
  EXPECT_EQ(verifier.check(encode_frame(heartbeat_message(), 4, 1, 1)), SignatureVerdict::unsigned_frame);
  // A new stream (link id 1) whose signature is right but whose time is years old.
  EXPECT_EQ(verifier.check(from_hex(kSignedHeartbeat)), SignatureVerdict::too_old);
  EXPECT_EQ(verifier.stats().accepted, 2u);
  EXPECT_EQ(verifier.stats().replayed, 1u);
  EXPECT_EQ(verifier.stats().bad_signature, 2u);
  EXPECT_EQ(verifier.stats().unsigned_frames, 1u);
  EXPECT_EQ(verifier.stats().too_old, 1u);
}

TEST(MavlinkSigning, StreamsAreKeptApartByComponentAndLink) {
  Verifier verifier(counting_key());
  Signer link0(counting_key(), 0), link1(counting_key(), 1);
  Bytes a = link0.sign(encode_frame(heartbeat_message(), 0, 1, 1));
  Bytes b = link1.sign(encode_frame(heartbeat_message(), 0, 1, 1));
  Bytes c = link0.sign(encode_frame(heartbeat_message(), 0, 1, 2));
  // b and c were signed after a, but each is the first of its own stream.
  EXPECT_EQ(verifier.check(c), SignatureVerdict::good);
  EXPECT_EQ(verifier.check(b), SignatureVerdict::good);
  EXPECT_EQ(verifier.check(a), SignatureVerdict::good);
}

TEST(MavlinkSigning, ParserWithAKeyDropsUnsignedOnlyWhenRequiredAndAlwaysDropsBadOnes) {
  Signer signer(counting_key(), 0);
  Parser parser;
  parser.verify_with(counting_key());
  std::vector<Frame> got = parser.feed(encode_frame(heartbeat_message(), 0, 1, 1));
  ASSERT_EQ(got.size(), 1u);
  EXPECT_FALSE(got[0].signature_verified);
  got = parser.feed(signer.sign(encode_frame(heartbeat_message(), 1, 1, 1)));
  ASSERT_EQ(got.size(), 1u);
  EXPECT_TRUE(got[0].signature_verified);
  EXPECT_EQ(got[0].message.payload.size(), find_message(msg::HEARTBEAT)->length);
  parser.require_signed(true);
  EXPECT_TRUE(parser.feed(encode_frame(heartbeat_message(), 2, 1, 1)).empty());
  Bytes bad = signer.sign(encode_frame(heartbeat_message(), 3, 1, 1));
  bad.back() ^= 0x80;
  EXPECT_TRUE(parser.feed(bad).empty());
  EXPECT_EQ(parser.stats().signing_dropped, 2u);
  EXPECT_EQ(parser.feed(signer.sign(encode_frame(heartbeat_message(), 4, 1, 1))).size(), 1u);
}

TEST(MavlinkSigning, ParserWithAKeySurvivesNoiseAndCutFrames) {
  Signer signer(counting_key(), 0);
  Parser parser;
  parser.verify_with(counting_key());
  parser.require_signed(true);
  std::mt19937 rng(13);
  std::uniform_int_distribution<int> byte(0, 255);
  size_t good = 0;
  for (int round = 0; round < 2000; ++round) {
    Bytes noise(static_cast<size_t>(byte(rng)));
    for (auto& b : noise) b = static_cast<uint8_t>(byte(rng));
    Bytes frame = signer.sign(encode_frame(heartbeat_message(), static_cast<uint8_t>(round), 1, 1));
    if (round % 3 == 0) frame.resize(frame.size() - 1 - static_cast<size_t>(byte(rng)) % 12);  // cut in the trailer
    for (auto& f : parser.feed(noise)) EXPECT_TRUE(f.signature_verified);
    for (auto& f : parser.feed(frame)) {
      EXPECT_TRUE(f.signature_verified);
      ++good;
    }
  }
  EXPECT_GT(good, 1000u);  // the whole frames behind noise and cut ones still come through
}

TEST(MavlinkSigning, SetupSigningHasCommonXmlsLayoutAndRoundTrips) {
  const MessageDef* def = find_message(msg::SETUP_SIGNING);
  ASSERT_NE(def, nullptr);
  EXPECT_EQ(def->crc_extra, 71);  // common.xml's SETUP_SIGNING
  EXPECT_EQ(def->length, 42);
  SetupSigning s{7, 1, counting_key().bytes, 123456789012345ull};
  auto back = unpack_setup_signing(pack(s));
  ASSERT_TRUE(back);
  EXPECT_EQ(back->target_system, 7);
  EXPECT_EQ(back->target_component, 1);
  EXPECT_EQ(back->secret_key, s.secret_key);
  EXPECT_EQ(back->initial_timestamp, s.initial_timestamp);
}

TEST(MavlinkSigning, KeysAreSixtyFourHexDigitsAndNeverAllZero) {
  std::string error;
  auto key = parse_signing_key("000102030405060708090a0b0c0d0e0f101112131415161718191A1B1C1D1E1F\n", error);
  ASSERT_TRUE(key) << error;
  EXPECT_EQ(key->bytes, counting_key().bytes);
  EXPECT_FALSE(parse_signing_key("abc", error));
  EXPECT_NE(error.find("64 hexadecimal digits"), std::string::npos);
  EXPECT_FALSE(parse_signing_key(std::string(63, '0') + "g", error));
  EXPECT_NE(error.find("only hexadecimal digits"), std::string::npos);
  EXPECT_FALSE(parse_signing_key(std::string(64, '0'), error));
  EXPECT_NE(error.find("all-zero"), std::string::npos);
}

}  // namespace
}  // namespace eamos::mavlink
