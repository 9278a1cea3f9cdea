// The table puts fields in MAVLink's wire order and knows each message's lengths.
#include <gtest/gtest.h>

#include <string>

#include "mavlink/messages.h"

namespace eamos::mavlink {
namespace {

std::vector<std::string> names(const MessageDef& def) {
  std::vector<std::string> out;
  for (const FieldDef& f : def.fields) out.emplace_back(f.name);
  return out;
}

TEST(MessageTable, HeartbeatPutsTheUint32First) {
  const MessageDef& hb = *find_message(msg::HEARTBEAT);
  EXPECT_EQ(names(hb), (std::vector<std::string>{"custom_mode", "type", "autopilot",
                                                  "base_mode", "system_status",
                                                  "mavlink_version"}));
  EXPECT_EQ(hb.fields[1].offset, 4);
}

TEST(MessageTable, ExtensionsStayLastAndUnsorted) {
  const MessageDef& ack = *find_message(msg::COMMAND_ACK);
  EXPECT_EQ(names(ack), (std::vector<std::string>{"command", "result", "progress",
                                                   "result_param2", "target_system",
                                                   "target_component"}));
}

TEST(MessageTable, LengthsMatchCommonXml) {
  struct Want { uint32_t id; int base; int full; };
  for (Want w : {Want{msg::HEARTBEAT, 9, 9}, Want{msg::SYS_STATUS, 31, 43}, Want{msg::ATTITUDE, 28, 28},
                 Want{msg::LOCAL_POSITION_NED, 28, 28}, Want{msg::GLOBAL_POSITION_INT, 28, 28},
                 Want{msg::COMMAND_INT, 35, 35}, Want{msg::COMMAND_LONG, 33, 33},
                 Want{msg::COMMAND_ACK, 3, 10}, Want{msg::SET_POSITION_TARGET_LOCAL_NED, 53, 53},
                 Want{msg::BATTERY_STATUS, 36, 54}, Want{msg::EXTENDED_SYS_STATE, 2, 2},
                 Want{msg::MISSION_REQUEST, 4, 5}, Want{msg::MISSION_REQUEST_LIST, 2, 3},
                 Want{msg::MISSION_COUNT, 4, 9}, Want{msg::MISSION_ACK, 3, 8},
                 Want{msg::MISSION_REQUEST_INT, 4, 5}, Want{msg::MISSION_ITEM_INT, 37, 38}}) {
    const MessageDef* def = find_message(w.id);
    ASSERT_NE(def, nullptr) << w.id;
    EXPECT_EQ(def->base_length, w.base) << def->name;
    EXPECT_EQ(def->length, w.full) << def->name;
  }
}

TEST(MessageTable, MissionItemIntPutsTheFourByteFieldsFirstAndTheMissionTypeLast) {
  const MessageDef& item = *find_message(msg::MISSION_ITEM_INT);
  EXPECT_EQ(names(item), (std::vector<std::string>{"param1", "param2", "param3", "param4", "x", "y", "z",
                                                    "seq", "command", "target_system", "target_component",
                                                    "frame", "current", "autocontinue", "mission_type"}));
  EXPECT_EQ(find_field(item, "seq")->offset, 28);
  EXPECT_EQ(find_field(item, "mission_type")->offset, 37);
}

TEST(MessageTable, UnknownIdIsNull) { EXPECT_EQ(find_message(12345), nullptr); }

}  // namespace
}  // namespace eamos::mavlink
