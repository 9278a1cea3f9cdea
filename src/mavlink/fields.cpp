#include "mavlink/fields.h"

#include <cassert>

namespace eamos::mavlink {

int field_offset(const MessageDef& def, std::string_view name, FieldType type, int index) {
  const FieldDef* f = find_field(def, name);
  int count = f ? (f->array_length == 0 ? 1 : f->array_length) : 0;
  bool ok = f && f->type == type && index >= 0 && index < count;
  assert(ok && "field name, type or index does not match the message table");
  if (!ok) return -1;
  return f->offset + index * type_size(type);
}

FieldWriter::FieldWriter(const MessageDef& def) : def_(def) {
  message_.id = def.id;
  message_.payload.assign(def.length, 0);
}

void FieldWriter::set_chars(std::string_view name, std::string_view text) {
  const FieldDef* f = find_field(def_, name);
  assert(f && f->type == FieldType::char_);
  if (!f || f->type != FieldType::char_) return;
  for (size_t i = 0; i < f->array_length; ++i)
    message_.payload[f->offset + i] = i < text.size() ? static_cast<uint8_t>(text[i]) : 0;
}

std::string FieldReader::get_chars(std::string_view name) const {
  const FieldDef* f = find_field(def_, name);
  if (!f || f->type != FieldType::char_) return {};
  std::string text;
  for (size_t i = 0; i < f->array_length && f->offset + i < message_.payload.size(); ++i) {
    char c = static_cast<char>(message_.payload[f->offset + i]);
    if (c == '\0') break;
    text.push_back(c);
  }
  return text;
}

}  // namespace eamos::mavlink
