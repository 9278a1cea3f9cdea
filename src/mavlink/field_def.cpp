#include "mavlink/field_def.h"

namespace eamos::mavlink {

int type_size(FieldType type) {
  switch (type) {
    case FieldType::u8: case FieldType::i8: case FieldType::char_: return 1;
    case FieldType::u16: case FieldType::i16: return 2;
    case FieldType::u32: case FieldType::i32: case FieldType::f32: return 4;
    case FieldType::u64: case FieldType::i64: case FieldType::f64: return 8;
  }
  return 1;
}

std::string_view type_name(FieldType type) {
  switch (type) {
    case FieldType::u8: return "uint8_t";
    case FieldType::i8: return "int8_t";
    case FieldType::u16: return "uint16_t";
    case FieldType::i16: return "int16_t";
    case FieldType::u32: return "uint32_t";
    case FieldType::i32: return "int32_t";
    case FieldType::u64: return "uint64_t";
    case FieldType::i64: return "int64_t";
    case FieldType::f32: return "float";
    case FieldType::f64: return "double";
    case FieldType::char_: return "char";
  }
  return "";
}

int field_size(const FieldDef& field) {
  int count = field.array_length == 0 ? 1 : field.array_length;
  return type_size(field.type) * count;
}

}  // namespace eamos::mavlink
