#pragma once
// The table of MAVLink messages eamos speaks (ids, fields, lengths, CRC_EXTRA), from
// MAVLink's common.xml. Fields are listed in the XML's order and the table sorts them into
// wire order by MAVLink's rule, so a reader can check each entry against the XML line by line.
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "mavlink/field_def.h"

namespace eamos::mavlink {

/// Message ids, named as in common.xml.
namespace msg {
inline constexpr uint32_t HEARTBEAT = 0;
inline constexpr uint32_t SYS_STATUS = 1;
inline constexpr uint32_t PARAM_REQUEST_READ = 20;
inline constexpr uint32_t PARAM_VALUE = 22;
inline constexpr uint32_t PARAM_SET = 23;
inline constexpr uint32_t ATTITUDE = 30;
inline constexpr uint32_t LOCAL_POSITION_NED = 32;
inline constexpr uint32_t GLOBAL_POSITION_INT = 33;
inline constexpr uint32_t MISSION_REQUEST = 40;
inline constexpr uint32_t MISSION_REQUEST_LIST = 43;
inline constexpr uint32_t MISSION_COUNT = 44;
inline constexpr uint32_t MISSION_ACK = 47;
inline constexpr uint32_t MISSION_REQUEST_INT = 51;
inline constexpr uint32_t MISSION_ITEM_INT = 73;
inline constexpr uint32_t COMMAND_INT = 75;
inline constexpr uint32_t COMMAND_LONG = 76;
inline constexpr uint32_t COMMAND_ACK = 77;
inline constexpr uint32_t SET_POSITION_TARGET_LOCAL_NED = 84;
inline constexpr uint32_t CAMERA_TRIGGER = 112;
inline constexpr uint32_t HIL_STATE_QUATERNION = 115;
inline constexpr uint32_t BATTERY_STATUS = 147;
inline constexpr uint32_t CAMERA_FEEDBACK = 180;
inline constexpr uint32_t EXTENDED_SYS_STATE = 245;
inline constexpr uint32_t STATUSTEXT = 253;
inline constexpr uint32_t SETUP_SIGNING = 256;
inline constexpr uint32_t CAMERA_IMAGE_CAPTURED = 263;
inline constexpr uint32_t ORBIT_EXECUTION_STATUS = 360;
}  // namespace msg

struct MessageDef {
  uint32_t id;
  std::string_view name;
  std::vector<FieldDef> fields;  ///< wire order, offsets filled in
  uint8_t base_length;           ///< payload bytes without extension fields
  uint8_t length;                ///< payload bytes with every field (what a decoder zero-fills to)
  uint8_t crc_extra;             ///< computed from name and fields by crc_extra()
};

/// Every message of the table, in id order.
std::span<const MessageDef> message_table();
/// The message with `id`, or nullptr when eamos does not know it.
const MessageDef* find_message(uint32_t id);
/// The field called `name` of `def`, or nullptr.
const FieldDef* find_field(const MessageDef& def, std::string_view name);

/// MAVLink's wire order: base fields stably sorted by element size, largest first, then the
/// extension fields in declaration order. Offsets are assigned along that order.
std::vector<FieldDef> wire_order(std::vector<FieldDef> declared);

}  // namespace eamos::mavlink
