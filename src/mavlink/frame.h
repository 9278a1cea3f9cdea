#pragma once
// MAVLink v2 framing: the Encoder turns messages into frames with a per-sender sequence
// number; the Parser turns a byte stream, chunked any way, back into messages.
//
// Frame layout: 0xFD, len, incompat_flags, compat_flags, seq, sysid, compid, msgid (24 bits,
// little-endian), payload (len bytes), CRC (little-endian) over everything after 0xFD up to
// the payload, then the message's CRC_EXTRA; and 13 signature bytes when incompat bit 0 is set.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "mavlink/fields.h"
#include "mavlink/signing.h"

namespace eamos::mavlink {

inline constexpr uint8_t kMagicV2 = 0xFD;
inline constexpr size_t kHeaderLength = 10;  ///< magic through msgid
inline constexpr size_t kCrcLength = 2;
inline constexpr size_t kSignatureLength = 13;
inline constexpr uint8_t kIncompatSigned = 0x01;

/// One decoded frame.
struct Frame {
  uint8_t seq = 0;
  uint8_t sysid = 0;
  uint8_t compid = 0;
  uint8_t incompat_flags = 0;
  uint8_t compat_flags = 0;
  uint8_t wire_length = 0;  ///< payload bytes as received, before zero-fill
  uint16_t checksum = 0;    ///< CRC as received (already checked), kept for logs and tests
  Message message;          ///< payload zero-filled to the message's full length
  bool signature_verified = false;  ///< signed, and its signature checked against the key
};

/// The payload as sent: trailing zero bytes dropped, but never below one byte (MAVLink v2).
std::vector<uint8_t> truncated(std::span<const uint8_t> payload);

/// Encodes one frame with the given header values; empty when `message.id` is not in the
/// table (its CRC_EXTRA is unknown, so no receiver could check it).
std::vector<uint8_t> encode_frame(const Message& message, uint8_t seq, uint8_t sysid,
                                  uint8_t compid);

/// One sender (system id, component id) with its own sequence counter.
struct Encoder {
  uint8_t sysid = 1;
  uint8_t compid = 1;
  uint8_t next_seq = 0;  ///< wraps from 255 to 0
  std::optional<Signer> signer;  ///< set: every frame is signed (MAVLink 2 signing)

  std::vector<uint8_t> encode(const Message& message);
};

/// What the parser threw away, by reason.
struct ParserStats {
  uint64_t frames = 0;          ///< good frames yielded
  uint64_t bad_crc = 0;         ///< known message, checksum wrong
  uint64_t unknown_id = 0;      ///< message id not in the table
  uint64_t unsupported = 0;     ///< signed frames without a key, and incompat flags we lack
  uint64_t skipped_bytes = 0;   ///< bytes dropped while searching for 0xFD
  uint64_t signing_dropped = 0; ///< with a key: unsigned (when required), badly signed, replayed
};

/// Incremental MAVLink v2 parser. A rejected candidate gives up only its 0xFD byte and the
/// search restarts right after it, so a real frame hidden behind garbage that happens to
/// contain 0xFD is never lost.
class Parser {
 public:
  /// Feeds more bytes and returns every frame they complete.
  std::vector<Frame> feed(std::span<const uint8_t> bytes);
  const ParserStats& stats() const { return stats_; }
  /// Drops the bytes of an unfinished frame (counted as skipped): over UDP a frame never
  /// spans two senders' datagrams, so another sender's bytes must not complete it.
  void discard_partial();
  /// Checks every signed frame against `key` (signing.h); a frame that fails is dropped.
  /// Unsigned frames pass until require_signed(true).
  void verify_with(SigningKey key) { verifier_.emplace(key); }
  void require_signed(bool on) { require_signed_ = on; }
  /// The verifier's counters; all zero without a key.
  SigningStats signing_stats() const { return verifier_ ? verifier_->stats() : SigningStats{}; }

 private:
  enum class Step { need_more, rejected, consumed };
  Step try_frame(std::vector<Frame>& out);
  void compact();

  /// With a key: signed frames checked, unsigned ones dropped once required.
  bool accept_signing(std::span<const uint8_t> frame, bool& verified);

  std::vector<uint8_t> buffer_;
  size_t head_ = 0;  ///< first unread byte of buffer_
  ParserStats stats_;
  std::optional<Verifier> verifier_;
  bool require_signed_ = false;
};

}  // namespace eamos::mavlink
