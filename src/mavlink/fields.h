#pragma once
// Little-endian reads and writes of MAVLink field values, and a writer/reader that address a
// payload's fields by their common.xml names through the message table, so the message
// structs never hard-code an offset.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "mavlink/messages.h"

namespace eamos::mavlink {

/// One message's id and payload (always the message's full length when built or parsed here).
struct Message {
  uint32_t id = 0;
  std::vector<uint8_t> payload;
};

/// The unsigned integer with T's size, the carrier of T's bytes.
template <typename T>
using Bits = std::conditional_t<sizeof(T) == 1, uint8_t,
             std::conditional_t<sizeof(T) == 2, uint16_t,
             std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>>;

/// Writes `value` little-endian at `offset`; the caller guarantees the room.
template <typename T>
void put_le(std::span<uint8_t> buf, size_t offset, T value) {
  auto bits = std::bit_cast<Bits<T>>(value);
  for (size_t i = 0; i < sizeof(T); ++i) buf[offset + i] = static_cast<uint8_t>(bits >> (8 * i));
}

/// Reads a little-endian T at `offset`; the caller guarantees the bytes exist.
template <typename T>
T get_le(std::span<const uint8_t> buf, size_t offset) {
  Bits<T> bits = 0;
  for (size_t i = 0; i < sizeof(T); ++i) bits |= static_cast<Bits<T>>(Bits<T>(buf[offset + i]) << (8 * i));
  return std::bit_cast<T>(bits);
}

/// The wire type a C++ value type is written as.
template <typename T>
constexpr FieldType field_type_of() {
  if constexpr (std::is_same_v<T, uint8_t>) return FieldType::u8;
  else if constexpr (std::is_same_v<T, int8_t>) return FieldType::i8;
  else if constexpr (std::is_same_v<T, uint16_t>) return FieldType::u16;
  else if constexpr (std::is_same_v<T, int16_t>) return FieldType::i16;
  else if constexpr (std::is_same_v<T, uint32_t>) return FieldType::u32;
  else if constexpr (std::is_same_v<T, int32_t>) return FieldType::i32;
  else if constexpr (std::is_same_v<T, uint64_t>) return FieldType::u64;
  else if constexpr (std::is_same_v<T, int64_t>) return FieldType::i64;
  else if constexpr (std::is_same_v<T, float>) return FieldType::f32;
  else return FieldType::f64;
}

/// Where a named field's element `index` lives, or -1 when the name, type or index does not
/// match the table (a programming error: the round-trip tests cover every field).
int field_offset(const MessageDef& def, std::string_view name, FieldType type, int index);

/// Builds one message's payload field by field.
class FieldWriter {
 public:
  /// `def` must outlive the writer; the payload starts as def.length zero bytes.
  explicit FieldWriter(const MessageDef& def);

  template <typename T>
  void set(std::string_view name, T value, int index = 0) {
    int at = field_offset(def_, name, field_type_of<T>(), index);
    if (at >= 0) put_le<T>(message_.payload, static_cast<size_t>(at), value);
  }
  /// A char[N] field: `text` cut to N bytes, NUL-padded (no terminator when exactly N).
  void set_chars(std::string_view name, std::string_view text);

  Message take() { return std::move(message_); }

 private:
  const MessageDef& def_;
  Message message_;
};

/// Reads a message's fields by name. The payload must be the message's full length.
class FieldReader {
 public:
  FieldReader(const MessageDef& def, const Message& message) : def_(def), message_(message) {}

  template <typename T>
  T get(std::string_view name, int index = 0) const {
    int at = field_offset(def_, name, field_type_of<T>(), index);
    if (at < 0 || static_cast<size_t>(at) + sizeof(T) > message_.payload.size()) return T{};
    return get_le<T>(message_.payload, static_cast<size_t>(at));
  }
  /// A char[N] field up to its first NUL.
  std::string get_chars(std::string_view name) const;

 private:
  const MessageDef& def_;
  const Message& message_;
};

}  // namespace eamos::mavlink
