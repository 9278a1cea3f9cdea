#pragma once
// Test-side references that share no code with src/mavlink: a bitwise CRC-16/MCRF4XX and a
// fixed-seed byte generator.
#include <cstdint>
#include <vector>

namespace eamos::mavlink::test {

/// CRC-16/MCRF4XX the textbook way: reflected polynomial 0x8408, init 0xFFFF, no final xor.
inline uint16_t bitwise_crc(const std::vector<uint8_t>& bytes) {
  uint16_t crc = 0xFFFF;
  for (uint8_t b : bytes) {
    crc ^= b;
    for (int i = 0; i < 8; ++i) crc = (crc & 1) ? (crc >> 1) ^ 0x8408 : crc >> 1;
  }
  return crc;
}

/// xorshift32: the same bytes on every run and every machine.
struct Random {
  uint32_t state = 0x2545F491;
  uint8_t byte() {
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    return static_cast<uint8_t>(state >> 24);
  }
};

}  // namespace eamos::mavlink::test
