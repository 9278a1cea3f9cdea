#include "mavlink/signing.h"

#include <openssl/evp.h>
#include <openssl/crypto.h>

#include <cctype>
#include <chrono>

#include "mavlink/crc.h"
#include "mavlink/frame.h"
#include "mavlink/messages.h"

namespace eamos::mavlink {

namespace {

constexpr size_t kMaxStreams = 64;
constexpr uint64_t kOneMinute = 60ull * 100000ull;  ///< in 10 µs units
constexpr int64_t kUnix2015 = 1420070400;           ///< 2015-01-01 00:00:00 UTC, Unix seconds

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

std::optional<SigningKey> parse_signing_key(std::string_view hex, std::string& error) {
  while (!hex.empty() && std::isspace(static_cast<unsigned char>(hex.front()))) hex.remove_prefix(1);
  while (!hex.empty() && std::isspace(static_cast<unsigned char>(hex.back()))) hex.remove_suffix(1);
  if (hex.size() != 64) {
    error = "a signing key is 64 hexadecimal digits (32 bytes), got " + std::to_string(hex.size()) +
            " characters; make one with `openssl rand -hex 32`";
    return std::nullopt;
  }
  SigningKey key;
  for (size_t i = 0; i < 32; ++i) {
    int hi = hex_digit(hex[2 * i]), lo = hex_digit(hex[2 * i + 1]);
    if (hi < 0 || lo < 0) {
      error = "a signing key holds only hexadecimal digits (0-9, a-f); make one with `openssl rand -hex 32`";
      return std::nullopt;
    }
    key.bytes[i] = static_cast<uint8_t>(hi * 16 + lo);
  }
  bool all_zero = true;
  for (uint8_t b : key.bytes) all_zero = all_zero && b == 0;
  if (all_zero) {
    error = "an all-zero signing key means \"signing off\" to an autopilot; make a real one with `openssl rand -hex 32`";
    return std::nullopt;
  }
  return key;
}

uint64_t signing_time_now() {
  using namespace std::chrono;
  int64_t us = duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
  int64_t since_2015 = us - kUnix2015 * 1000000;
  return since_2015 > 0 ? static_cast<uint64_t>(since_2015 / 10) : 0;
}

std::array<uint8_t, 6> signature_of(const SigningKey& key, std::span<const uint8_t> frame, uint8_t link_id,
                                    uint64_t timestamp) {
  std::array<uint8_t, 7> tail{link_id};
  for (int i = 0; i < 6; ++i) tail[1 + i] = static_cast<uint8_t>(timestamp >> (8 * i));
  std::array<uint8_t, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  EVP_MD_CTX* ctx = EVP_MD_CTX_new();
  bool ok = ctx && EVP_DigestInit_ex(ctx, EVP_sha256(), nullptr) == 1 &&
            EVP_DigestUpdate(ctx, key.bytes.data(), key.bytes.size()) == 1 &&
            EVP_DigestUpdate(ctx, frame.data(), frame.size()) == 1 &&
            EVP_DigestUpdate(ctx, tail.data(), tail.size()) == 1 && EVP_DigestFinal_ex(ctx, digest.data(), &length) == 1;
  EVP_MD_CTX_free(ctx);
  std::array<uint8_t, 6> out{};
  // A failed hash (out of memory) gives a signature of zeros, which no peer accepts: the
  // frame is lost, never sent or taken unsigned.
  if (ok && length >= 6)
    for (int i = 0; i < 6; ++i) out[i] = digest[i];
  return out;
}

std::vector<uint8_t> Signer::sign(std::vector<uint8_t> frame) {
  if (frame.size() < kHeaderLength + kCrcLength || frame[0] != kMagicV2) return {};
  const uint32_t id = frame[7] | (uint32_t(frame[8]) << 8) | (uint32_t(frame[9]) << 16);
  const MessageDef* def = find_message(id);
  if (!def) return {};
  frame[2] |= kIncompatSigned;
  const size_t crc_at = frame.size() - kCrcLength;
  uint16_t crc = crc_calculate(std::span(frame).subspan(1, crc_at - 1));
  crc = crc_accumulate(def->crc_extra, crc);
  frame[crc_at] = static_cast<uint8_t>(crc & 0xFF);
  frame[crc_at + 1] = static_cast<uint8_t>(crc >> 8);
  // Monotonic: the clock, unless that would not be later than the last frame's time.
  uint64_t t = std::max(signing_time_now(), last_ + 1) & 0xFFFFFFFFFFFFull;
  last_ = t;
  std::array<uint8_t, 6> sig = signature_of(key_, frame, link_id_, t);
  frame.push_back(link_id_);
  for (int i = 0; i < 6; ++i) frame.push_back(static_cast<uint8_t>(t >> (8 * i)));
  frame.insert(frame.end(), sig.begin(), sig.end());
  return frame;
}

const char* verdict_name(SignatureVerdict v) {
  switch (v) {
    case SignatureVerdict::good: return "good";
    case SignatureVerdict::unsigned_frame: return "unsigned";
    case SignatureVerdict::bad_signature: return "bad signature";
    case SignatureVerdict::replayed: return "replayed (timestamp not newer than its stream's)";
    case SignatureVerdict::too_old: return "too old (a new stream more than a minute behind)";
  }
  return "bad signature";
}

SignatureVerdict Verifier::check(std::span<const uint8_t> frame) {
  if (frame.size() < kHeaderLength + kCrcLength || (frame[2] & kIncompatSigned) == 0 ||
      frame.size() < kHeaderLength + kCrcLength + kSignatureLength) {
    ++stats_.unsigned_frames;
    return SignatureVerdict::unsigned_frame;
  }
  const size_t signed_part = frame.size() - kSignatureLength;
  const uint8_t link_id = frame[signed_part];
  uint64_t t = 0;
  for (int i = 0; i < 6; ++i) t |= uint64_t(frame[signed_part + 1 + i]) << (8 * i);
  std::array<uint8_t, 6> want = signature_of(key_, frame.subspan(0, signed_part), link_id, t);
  // Constant time: how many leading bytes matched must not show in the timing.
  if (CRYPTO_memcmp(want.data(), frame.data() + signed_part + 7, 6) != 0) {
    ++stats_.bad_signature;
    return SignatureVerdict::bad_signature;
  }
  auto stream = std::make_tuple(frame[5], frame[6], link_id);
  auto it = streams_.find(stream);
  if (it != streams_.end() && t <= it->second) {
    ++stats_.replayed;
    return SignatureVerdict::replayed;
  }
  uint64_t local = std::max(newest_, signing_time_now());
  if (it == streams_.end()) {
    if (t + kOneMinute < local) {
      ++stats_.too_old;
      return SignatureVerdict::too_old;
    }
    if (streams_.size() >= kMaxStreams) streams_.erase(streams_.begin());
    it = streams_.emplace(stream, t).first;
  }
  it->second = t;
  newest_ = std::max(newest_, t);
  ++stats_.accepted;
  return SignatureVerdict::good;
}

}  // namespace eamos::mavlink
