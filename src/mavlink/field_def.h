#pragma once
// How one MAVLink message field is described: its wire type, name and array length. The
// message table (messages.h) and the CRC_EXTRA computation (crc.h) both read this.
#include <cstdint>
#include <string_view>

namespace eamos::mavlink {

/// The wire types of MAVLink. `char_` is a character of a char[N] string.
enum class FieldType : uint8_t { u8, i8, u16, i16, u32, i32, u64, i64, f32, f64, char_ };

struct FieldDef {
  FieldType type;
  std::string_view name;
  uint8_t array_length = 0;  ///< 0 for a scalar, N for type[N]
  bool extension = false;    ///< after the `<extensions/>` tag: not sorted, not in CRC_EXTRA
  uint8_t offset = 0;        ///< byte offset in the payload; filled in by the message table
};

/// Size in bytes of one element of `type`.
int type_size(FieldType type);
/// The C type name MAVLink's CRC_EXTRA hashes ("uint8_t", "float", "char", ...).
std::string_view type_name(FieldType type);
/// Bytes the field takes in the payload (element size times array length).
int field_size(const FieldDef& field);

}  // namespace eamos::mavlink
