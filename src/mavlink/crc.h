#pragma once
// MAVLink's checksum: CRC-16/MCRF4XX (the "X.25" of the MAVLink docs), and CRC_EXTRA, the
// per-message seed byte that makes a frame's CRC fail when sender and receiver disagree on a
// message's layout.
#include <cstdint>
#include <span>
#include <string_view>

#include "mavlink/field_def.h"

namespace eamos::mavlink {

inline constexpr uint16_t kCrcInit = 0xFFFF;

/// Folds one byte into `crc` (MAVLink's crc_accumulate).
uint16_t crc_accumulate(uint8_t byte, uint16_t crc);
/// Folds every byte of `bytes` into `crc`, which starts at kCrcInit for a fresh checksum.
uint16_t crc_calculate(std::span<const uint8_t> bytes, uint16_t crc = kCrcInit);

/// CRC_EXTRA of a message from its name and its fields in wire order: the CRC of
/// "NAME " then "type name " per base field (plus the array length byte for arrays), folded
/// to one byte. Extension fields are skipped, so adding them keeps old readers compatible.
uint8_t crc_extra(std::string_view message_name, std::span<const FieldDef> wire_fields);

}  // namespace eamos::mavlink
