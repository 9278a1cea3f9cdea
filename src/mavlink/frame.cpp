#include "mavlink/frame.h"

#include <algorithm>

#include "mavlink/crc.h"

namespace eamos::mavlink {

std::vector<uint8_t> truncated(std::span<const uint8_t> payload) {
  size_t n = payload.size();
  while (n > 1 && payload[n - 1] == 0) --n;
  return {payload.begin(), payload.begin() + static_cast<std::ptrdiff_t>(n)};
}

std::vector<uint8_t> encode_frame(const Message& message, uint8_t seq, uint8_t sysid,
                                  uint8_t compid) {
  const MessageDef* def = find_message(message.id);
  if (!def) return {};
  std::vector<uint8_t> payload = truncated(message.payload);
  if (payload.empty()) payload.push_back(0);
  if (payload.size() > 255) payload.resize(255);
  std::vector<uint8_t> out{kMagicV2,
                           static_cast<uint8_t>(payload.size()),
                           0,
                           0,
                           seq,
                           sysid,
                           compid,
                           static_cast<uint8_t>(message.id),
                           static_cast<uint8_t>(message.id >> 8),
                           static_cast<uint8_t>(message.id >> 16)};
  out.insert(out.end(), payload.begin(), payload.end());
  uint16_t crc = crc_calculate(std::span(out).subspan(1));
  crc = crc_accumulate(def->crc_extra, crc);
  out.push_back(static_cast<uint8_t>(crc & 0xFF));
  out.push_back(static_cast<uint8_t>(crc >> 8));
  return out;
}

std::vector<uint8_t> Encoder::encode(const Message& message) {
  // uint8_t arithmetic wraps 255 -> 0, as MAVLink's sequence number does.
  std::vector<uint8_t> frame = encode_frame(message, next_seq++, sysid, compid);
  return signer ? signer->sign(std::move(frame)) : frame;
}

std::vector<Frame> Parser::feed(std::span<const uint8_t> bytes) {
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
  std::vector<Frame> out;
  while (head_ < buffer_.size()) {
    if (buffer_[head_] != kMagicV2) {
      ++head_;
      ++stats_.skipped_bytes;
      continue;
    }
    Step step = try_frame(out);
    if (step == Step::need_more) break;
    if (step == Step::rejected) ++head_;
  }
  compact();
  return out;
}

Parser::Step Parser::try_frame(std::vector<Frame>& out) {
  std::span<const uint8_t> avail = std::span(buffer_).subspan(head_);
  if (avail.size() < kHeaderLength) return Step::need_more;
  uint8_t len = avail[1];
  uint8_t incompat = avail[2];
  uint32_t id = avail[7] | (uint32_t(avail[8]) << 8) | (uint32_t(avail[9]) << 16);
  // Judge the header before waiting for the body, so garbage that looks like a long frame
  // does not hold back the real frames behind it.
  if ((incompat & ~kIncompatSigned) != 0) {
    ++stats_.unsupported;
    return Step::rejected;
  }
  const MessageDef* def = find_message(id);
  if (!def) {
    ++stats_.unknown_id;
    return Step::rejected;
  }
  bool is_signed = (incompat & kIncompatSigned) != 0;
  size_t total = kHeaderLength + len + kCrcLength + (is_signed ? kSignatureLength : 0);
  if (avail.size() < total) return Step::need_more;
  uint16_t crc = crc_calculate(avail.subspan(1, kHeaderLength - 1 + len));
  crc = crc_accumulate(def->crc_extra, crc);
  uint16_t sent = avail[kHeaderLength + len] | (uint16_t(avail[kHeaderLength + len + 1]) << 8);
  if (crc != sent) {
    ++stats_.bad_crc;
    return Step::rejected;
  }
  // The checksum holds, so this is a real frame: drop it whole if we cannot handle it.
  head_ += total;
  bool verified = false;
  if (verifier_) {
    if (!accept_signing(avail.subspan(0, total), verified)) return Step::consumed;
  } else if (incompat != 0) {
    ++stats_.unsupported;
    return Step::consumed;
  }
  Frame frame{avail[4], avail[5], avail[6], incompat, avail[3], len, sent, {id, {}}, verified};
  auto payload = avail.subspan(kHeaderLength, len);
  frame.message.payload.assign(payload.begin(), payload.end());
  // Zero-fill what the sender truncated; ignore extension bytes newer than our table.
  frame.message.payload.resize(def->length, 0);
  out.push_back(std::move(frame));
  ++stats_.frames;
  return Step::consumed;
}

bool Parser::accept_signing(std::span<const uint8_t> frame, bool& verified) {
  SignatureVerdict v = verifier_->check(frame);
  verified = v == SignatureVerdict::good;
  if (verified || (v == SignatureVerdict::unsigned_frame && !require_signed_)) return true;
  ++stats_.signing_dropped;
  return false;
}

void Parser::discard_partial() {
  stats_.skipped_bytes += buffer_.size() - head_;
  buffer_.clear();
  head_ = 0;
}

void Parser::compact() {
  // Erasing only now and then keeps feeding a long stream linear.
  if (head_ == buffer_.size()) {
    buffer_.clear();
    head_ = 0;
  } else if (head_ > 4096) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(head_));
    head_ = 0;
  }
}

}  // namespace eamos::mavlink
