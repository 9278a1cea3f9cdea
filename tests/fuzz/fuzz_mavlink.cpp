// libFuzzer target of the MAVLink parser, with and without a signing key: any bytes, cut into
// chunks the input itself chooses, must give frames whose payloads have their message's full length and survive a re-encode —
// never a crash, a hang or a read past the buffer.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "mavlink/frame.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eamos::mavlink;
  if (size == 0) return 0;
  Parser parser;
  // Its top bit: check signatures too (signed frames verified, unsigned ones required or not).
  if (data[0] & 0x80) {
    SigningKey key;
    key.bytes.fill(0x5A);
    parser.verify_with(key);
    parser.require_signed(data[0] & 0x40);
  }
  std::vector<Frame> frames;
  // The first byte picks the chunk size, so the fuzzer explores frames split anywhere.
  std::size_t chunk = 1 + data[0] % 64;
  for (std::size_t at = 1; at < size; at += chunk) {
    auto got = parser.feed(std::span(data + at, std::min(chunk, size - at)));
    frames.insert(frames.end(), got.begin(), got.end());
  }
  for (const Frame& f : frames) {
    const MessageDef* def = find_message(f.message.id);
    if (!def || f.message.payload.size() != def->length) std::abort();
    Parser again;
    auto back = again.feed(encode_frame(f.message, f.seq, f.sysid, f.compid));
    if (back.size() != 1 || back[0].message.payload != f.message.payload) std::abort();
  }
  return 0;
}
