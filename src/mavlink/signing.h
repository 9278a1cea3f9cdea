#pragma once
// MAVLink 2 message signing (mavlink.io "Message Signing"): a 13-byte trailer of link id,
// 48-bit timestamp (10 µs units since 2015-01-01 00:00:00 UTC) and the first 6 bytes of
// SHA-256(secret key ‖ header ‖ payload ‖ CRC ‖ link id ‖ timestamp). The hash is OpenSSL's
// libcrypto; nothing here is cryptography of our own.
//
// Receiving follows the spec's rules: a frame is accepted only when its signature matches the
// shared key and its timestamp is newer than the last one accepted from the same stream
// (system id, component id, link id); a stream seen for the first time must not be more than
// one minute behind the newest time known here. Everything else is dropped and counted.
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <vector>

namespace eamos::mavlink {

struct SigningKey {
  std::array<uint8_t, 32> bytes{};
};

/// A key from 64 hexadecimal digits (surrounding blanks and a final newline allowed); empty
/// with `error` saying what is wrong otherwise.
std::optional<SigningKey> parse_signing_key(std::string_view hex, std::string& error);

/// The signing clock now: 10 µs units since 2015-01-01 00:00:00 UTC, from the system clock.
uint64_t signing_time_now();

/// The 6 signature bytes of a frame (`frame`: magic through CRC, the signed flag already
/// set) with `link_id` and `timestamp`.
std::array<uint8_t, 6> signature_of(const SigningKey& key, std::span<const uint8_t> frame, uint8_t link_id,
                                    uint64_t timestamp);

/// Signs outgoing frames: sets the incompat flag, recomputes the CRC and appends the trailer.
/// Timestamps never repeat and never go back, also when the system clock does.
class Signer {
 public:
  Signer(SigningKey key, uint8_t link_id) : key_(key), link_id_(link_id) {}
  /// `frame` as encode_frame() makes it (unsigned, MAVLink 2); empty in, empty out.
  std::vector<uint8_t> sign(std::vector<uint8_t> frame);

 private:
  SigningKey key_;
  uint8_t link_id_;
  uint64_t last_ = 0;
};

enum class SignatureVerdict { good, unsigned_frame, bad_signature, replayed, too_old };
const char* verdict_name(SignatureVerdict v);

/// What a Verifier has dropped, by reason.
struct SigningStats {
  uint64_t accepted = 0;
  uint64_t unsigned_frames = 0;
  uint64_t bad_signature = 0;
  uint64_t replayed = 0;   ///< timestamp not newer than its stream's last
  uint64_t too_old = 0;    ///< a new stream more than a minute behind
};

/// Checks incoming frames of one link against the shared key.
class Verifier {
 public:
  explicit Verifier(SigningKey key) : key_(key) {}
  /// `frame`: one whole frame, magic through the signature (CRC already checked).
  SignatureVerdict check(std::span<const uint8_t> frame);
  const SigningStats& stats() const { return stats_; }

 private:
  SigningKey key_;
  /// (sysid, compid, link id) -> last accepted timestamp. Only frames with a good signature
  /// make an entry, so without the key nobody can fill it; the bound is still there.
  std::map<std::tuple<uint8_t, uint8_t, uint8_t>, uint64_t> streams_;
  uint64_t newest_ = 0;  ///< newest timestamp accepted (or the local clock, if later)
  SigningStats stats_;
};

}  // namespace eamos::mavlink
