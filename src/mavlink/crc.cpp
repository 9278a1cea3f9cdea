#include "mavlink/crc.h"

namespace eamos::mavlink {

uint16_t crc_accumulate(uint8_t byte, uint16_t crc) {
  uint8_t tmp = byte ^ static_cast<uint8_t>(crc & 0xFF);
  tmp ^= static_cast<uint8_t>(tmp << 4);
  return static_cast<uint16_t>((crc >> 8) ^ (tmp << 8) ^ (tmp << 3) ^ (tmp >> 4));
}

uint16_t crc_calculate(std::span<const uint8_t> bytes, uint16_t crc) {
  for (uint8_t b : bytes) crc = crc_accumulate(b, crc);
  return crc;
}

namespace {

uint16_t crc_text(std::string_view text, uint16_t crc) {
  for (char c : text) crc = crc_accumulate(static_cast<uint8_t>(c), crc);
  return crc;
}

}  // namespace

uint8_t crc_extra(std::string_view message_name, std::span<const FieldDef> wire_fields) {
  uint16_t crc = crc_text(message_name, kCrcInit);
  crc = crc_text(" ", crc);
  for (const FieldDef& f : wire_fields) {
    if (f.extension) continue;
    crc = crc_text(type_name(f.type), crc);
    crc = crc_text(" ", crc);
    crc = crc_text(f.name, crc);
    crc = crc_text(" ", crc);
    if (f.array_length != 0) crc = crc_accumulate(f.array_length, crc);
  }
  return static_cast<uint8_t>((crc & 0xFF) ^ (crc >> 8));
}

}  // namespace eamos::mavlink
