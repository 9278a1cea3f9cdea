// The checksum is CRC-16/MCRF4XX, and each message's CRC_EXTRA, computed from the table's
// fields by MAVLink's algorithm, equals the value published in MAVLink's generated headers.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "helpers.h"
#include "mavlink/crc.h"
#include "mavlink/messages.h"

namespace eamos::mavlink {
namespace {

std::vector<uint8_t> bytes_of(const std::string& s) { return {s.begin(), s.end()}; }

TEST(Crc, CheckValueOfMcrf4xxIs6F91) {
  EXPECT_EQ(crc_calculate(bytes_of("123456789")), 0x6F91);
}

TEST(Crc, MatchesTheBitwiseReference) {
  test::Random rng;
  std::vector<uint8_t> data;
  for (int i = 0; i < 1000; ++i) data.push_back(rng.byte());
  EXPECT_EQ(crc_calculate(data), test::bitwise_crc(data));
}

TEST(Crc, CalculateContinuesFromAGivenCrc) {
  auto all = bytes_of("123456789");
  uint16_t head = crc_calculate(std::span(all).first(4));
  EXPECT_EQ(crc_calculate(std::span(all).subspan(4), head), 0x6F91);
}

// Published CRC_EXTRA values: MAVLINK_MSG_ID_<NAME>_CRC of the generated common.xml headers
// (mavlink/c_library_v2), cross-checked with paparazzi's crc_extra[] table for ids below 78.
const std::map<uint32_t, uint8_t> kPublished = {
    {msg::HEARTBEAT, 50},           {msg::SYS_STATUS, 124},
    {msg::PARAM_REQUEST_READ, 214}, {msg::PARAM_VALUE, 220},
    {msg::PARAM_SET, 168},          {msg::ATTITUDE, 39},
    {msg::LOCAL_POSITION_NED, 185}, {msg::GLOBAL_POSITION_INT, 104},
    {msg::COMMAND_INT, 158},        {msg::COMMAND_LONG, 152},
    {msg::COMMAND_ACK, 143},        {msg::SET_POSITION_TARGET_LOCAL_NED, 143},
    {msg::BATTERY_STATUS, 154},     {msg::EXTENDED_SYS_STATE, 130},
    {msg::STATUSTEXT, 83},          {msg::SETUP_SIGNING, 71},
    {msg::CAMERA_TRIGGER, 174},     {msg::CAMERA_FEEDBACK, 52},
    {msg::HIL_STATE_QUATERNION, 4},
    {msg::CAMERA_IMAGE_CAPTURED, 133}, {msg::ORBIT_EXECUTION_STATUS, 11},
    {msg::MISSION_REQUEST, 230},    {msg::MISSION_REQUEST_LIST, 132},
    {msg::MISSION_COUNT, 221},      {msg::MISSION_ACK, 153},
    {msg::MISSION_REQUEST_INT, 196}, {msg::MISSION_ITEM_INT, 38},
};

TEST(CrcExtra, EveryTableMessageMatchesThePublishedValue) {
  ASSERT_EQ(message_table().size(), kPublished.size());
  for (const MessageDef& def : message_table()) {
    SCOPED_TRACE(std::string(def.name));
    ASSERT_TRUE(kPublished.contains(def.id));
    EXPECT_EQ(def.crc_extra, kPublished.at(def.id));
  }
}

TEST(CrcExtra, IgnoresExtensionFields) {
  const MessageDef& ack = *find_message(msg::COMMAND_ACK);
  std::vector<FieldDef> base;
  for (const FieldDef& f : ack.fields)
    if (!f.extension) base.push_back(f);
  EXPECT_EQ(crc_extra(ack.name, base), ack.crc_extra);
}

TEST(CrcExtra, HashesTheArrayLength) {
  std::vector<FieldDef> five{{FieldType::u16, "v", 5}};
  std::vector<FieldDef> six{{FieldType::u16, "v", 6}};
  EXPECT_NE(crc_extra("M", five), crc_extra("M", six));
}

}  // namespace
}  // namespace eamos::mavlink
