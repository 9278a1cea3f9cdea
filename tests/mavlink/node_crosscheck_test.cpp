// Our codec against node-mavlink, an independent implementation (tests/mavlink/node/): every
// message of our table, written by us and read by it, written by it and read by us, with
// values in every byte so a swapped offset, a wrong CRC_EXTRA or a different truncation shows.
#include <gtest/gtest.h>

#include <algorithm>

#include "mavlink/frame.h"
#include "mavlink/payloads.h"
#include "node_mavlink.h"

namespace eamos::mavlink {
namespace {

using nlohmann::json;
using test::NodeRun;

/// How a generated message is filled: every field non-zero (nothing to truncate); only the
/// first field in wire order, set small (0x0102 for integers, so an integer field is cut
/// after its low bytes; 2.0 for floats); or all zero (cut to the one byte MAVLink v2 keeps).
enum class Fill { every_field, first_field_small, zero };

/// Element `index` of field `f`, number `k` (1, 2, ...) of the message: distinct and non-zero
/// in its top byte, or the small value of Fill::first_field_small.
void set_element(FieldWriter& w, const FieldDef& f, int index, int k, bool small) {
  auto put = [&]<typename T>(T value, T small_value) {
    w.set<T>(f.name, small ? small_value : value, index);
  };
  switch (f.type) {
    case FieldType::u8: put(static_cast<uint8_t>(0x80 + k), uint8_t{2}); break;
    case FieldType::i8: put(static_cast<int8_t>(-3 - k), int8_t{2}); break;
    case FieldType::u16: put(static_cast<uint16_t>(0xA000 + 7 * k), uint16_t{0x0102}); break;
    case FieldType::i16: put(static_cast<int16_t>(-1000 - k), int16_t{0x0102}); break;
    case FieldType::u32:
      put(0xC0000000u + 12345u * static_cast<uint32_t>(k), uint32_t{0x0102});
      break;
    case FieldType::i32: put(int32_t{-100000} - 77 * k, int32_t{0x0102}); break;
    case FieldType::u64:
      put(uint64_t{0xF000000000000000ULL} + static_cast<uint64_t>(k), uint64_t{0x0102});
      break;
    case FieldType::i64: put(int64_t{-(1LL << 40)} - k, int64_t{0x0102}); break;
    case FieldType::f32: put(-12.275f + 1.5f * static_cast<float>(k), 2.0f); break;
    case FieldType::f64: put(-1e9 - 0.1 * k, 2.0); break;
    case FieldType::char_: put(static_cast<uint8_t>('a' + k % 26), uint8_t{'b'}); break;
  }
}

Message make_message(const MessageDef& def, Fill fill) {
  FieldWriter w(def);
  int k = 0;
  for (const FieldDef& f : def.fields) {
    for (int e = 0; e < std::max<int>(1, f.array_length); ++e) {
      ++k;
      if (fill == Fill::every_field) set_element(w, f, e, k, false);
      if (fill == Fill::first_field_small && k == 1) set_element(w, f, e, k, true);
    }
  }
  return w.take();
}

/// One generated message and the header it is sent with.
struct Sample {
  Message message;
  uint8_t seq, sysid, compid;
  const MessageDef* def;
};

/// Every message of our table in each fill, with distinct header values.
std::vector<Sample> samples() {
  std::vector<Sample> out;
  uint8_t n = 250;  // sequence numbers wrap from 255 to 0 along the way
  for (Fill fill : {Fill::every_field, Fill::first_field_small, Fill::zero}) {
    for (const MessageDef& def : message_table()) {
      out.push_back({make_message(def, fill), n, static_cast<uint8_t>(200 + n % 50),
                     static_cast<uint8_t>(n * 3 + 1), &def});
      ++n;
    }
  }
  return out;
}

std::string where(const Sample& s, size_t i) {
  return "frame " + std::to_string(i) + " (" + std::string(s.def->name) + ", seq " +
         std::to_string(s.seq) + ")";
}

TEST(NodeMavlinkCrosscheck, NodeMavlinkIsInstalled) {
  EXPECT_EQ(test::node_mavlink_missing(), "");
}

TEST(NodeMavlinkCrosscheck, ItsTableAgreesWithOursOnCrcExtraLengthsAndOffsets) {
  ASSERT_EQ(test::node_mavlink_missing(), "");
  std::string ids;
  for (const MessageDef& def : message_table()) ids += " " + std::to_string(def.id);
  NodeRun run = test::run_node_mavlink("describe" + ids);
  ASSERT_EQ(run.exit_code, 0) << run.other_output;
  ASSERT_EQ(run.lines.size(), message_table().size()) << run.other_output;
  for (size_t m = 0; m < run.lines.size(); ++m) {
    const MessageDef& def = message_table()[m];
    const json& theirs = run.lines[m];
    EXPECT_EQ(theirs["name"], def.name);
    EXPECT_EQ(theirs["crc_extra"], def.crc_extra) << def.name;
    EXPECT_EQ(theirs["length"], def.length) << def.name << ": payload length with extensions";
    for (const FieldDef& f : def.fields) {
      const json* tf = nullptr;
      for (const json& x : theirs["fields"])
        if (x["name"] == f.name) tf = &x;
      ASSERT_NE(tf, nullptr) << def.name << "." << f.name << " missing in node-mavlink";
      EXPECT_EQ((*tf)["offset"], f.offset) << def.name << "." << f.name;
      EXPECT_EQ((*tf)["extension"], f.extension) << def.name << "." << f.name;
      EXPECT_EQ((*tf)["length"], f.array_length) << def.name << "." << f.name;
    }
  }
}

TEST(NodeMavlinkCrosscheck, DecodesEveryMessageWeEncodeIncludingTruncatedOnes) {
  ASSERT_EQ(test::node_mavlink_missing(), "");
  test::ScratchDir dir;
  std::vector<Sample> all = samples();
  std::vector<uint8_t> stream;
  std::vector<size_t> wire_lengths;
  for (const Sample& s : all) {
    auto frame = encode_frame(s.message, s.seq, s.sysid, s.compid);
    wire_lengths.push_back(frame[1]);
    stream.insert(stream.end(), frame.begin(), frame.end());
  }
  test::write_file(dir.file("ours.bin"), stream);

  NodeRun run = test::run_node_mavlink("decode '" + dir.file("ours.bin") + "'");
  ASSERT_EQ(run.exit_code, 0) << run.other_output;
  EXPECT_EQ(run.summary()["crc_errors"], 0) << "node-mavlink rejected the checksum of some frames";
  EXPECT_EQ(run.summary()["unknown"], 0);
  auto frames = run.frames();
  ASSERT_EQ(frames.size(), all.size()) << run.other_output;
  for (size_t i = 0; i < all.size(); ++i) {
    const Sample& s = all[i];
    const json& f = frames[i];
    EXPECT_EQ(f["msgid"], s.def->id) << where(s, i);
    EXPECT_EQ(f["seq"], s.seq) << where(s, i);
    EXPECT_EQ(f["sysid"], s.sysid) << where(s, i);
    EXPECT_EQ(f["compid"], s.compid) << where(s, i);
    EXPECT_EQ(f["len"], wire_lengths[i]) << where(s, i);
    test::expect_same_fields(*s.def, s.message, f["fields"], where(s, i));
  }
  // The fills really exercised truncation: to one byte, and inside a field.
  EXPECT_EQ(wire_lengths.back(), 1u);
  EXPECT_EQ(frames[message_table().size()]["len"], 2) << "HEARTBEAT with only custom_mode 0x0102";
}

/// Our messages as node-mavlink's encode spec: one JSON line each, values as it prints them.
std::string spec_lines(const std::vector<Sample>& all) {
  std::string out;
  for (const Sample& s : all) {
    json fields = json::object();
    for (const FieldDef& f : s.def->fields) {
      if (!f.array_length) {
        fields[std::string(f.name)] = test::our_value(*s.def, s.message, f, 0);
        continue;
      }
      if (f.type == FieldType::char_) {
        fields[std::string(f.name)] = FieldReader(*s.def, s.message).get_chars(f.name);
        continue;
      }
      json values = json::array();
      for (int e = 0; e < f.array_length; ++e)
        values.push_back(test::our_value(*s.def, s.message, f, e));
      fields[std::string(f.name)] = values;
    }
    out += json{{"msgid", s.def->id}, {"sysid", s.sysid}, {"compid", s.compid}, {"seq", s.seq},
                {"fields", fields}}.dump() + "\n";
  }
  return out;
}

TEST(NodeMavlinkCrosscheck, WeDecodeEveryMessageItEncodesAndWriteTheSameBytes) {
  ASSERT_EQ(test::node_mavlink_missing(), "");
  test::ScratchDir dir;
  std::vector<Sample> all = samples();
  std::ofstream(dir.file("spec.jsonl")) << spec_lines(all);
  NodeRun run = test::run_node_mavlink("encode '" + dir.file("spec.jsonl") + "' '" +
                                       dir.file("theirs.bin") + "'");
  ASSERT_EQ(run.exit_code, 0) << run.other_output;
  std::vector<uint8_t> theirs = test::read_file(dir.file("theirs.bin"));

  // Cut their stream into frames by the length byte, to compare frame by frame below.
  std::vector<std::vector<uint8_t>> their_frames;
  for (size_t at = 0; at + kHeaderLength <= theirs.size();) {
    size_t n = kHeaderLength + theirs[at + 1] + kCrcLength;
    size_t end = std::min(at + n, theirs.size());
    their_frames.emplace_back(theirs.begin() + at, theirs.begin() + end);
    at += n;
  }

  Parser parser;
  std::vector<Frame> frames = parser.feed(theirs);
  EXPECT_EQ(parser.stats().bad_crc, 0u);
  EXPECT_EQ(parser.stats().unknown_id, 0u);
  EXPECT_EQ(parser.stats().skipped_bytes, 0u);
  ASSERT_EQ(frames.size(), all.size());
  ASSERT_EQ(their_frames.size(), all.size());
  for (size_t i = 0; i < all.size(); ++i) {
    const Sample& s = all[i];
    EXPECT_EQ(frames[i].message.id, s.def->id) << where(s, i);
    EXPECT_EQ(frames[i].seq, s.seq) << where(s, i);
    EXPECT_EQ(frames[i].sysid, s.sysid) << where(s, i);
    EXPECT_EQ(frames[i].compid, s.compid) << where(s, i);
    // Zero-filled to full length, so equal payloads mean every field is equal.
    EXPECT_EQ(frames[i].message.payload, s.message.payload) << where(s, i);
    std::vector<uint8_t> ours = encode_frame(s.message, s.seq, s.sysid, s.compid);
    bool all_zero = std::ranges::all_of(s.message.payload, [](uint8_t b) { return b == 0; });
    if (all_zero) {
      // The one known difference: MAVLink keeps the first payload byte even when the payload is
      // all zero (we send 1 byte); node-mavlink 2.3.0 sends none. We must still read its frame
      // (checked above), and it reads ours (the test before).
      EXPECT_EQ(ours[1], 1) << where(s, i);
      EXPECT_EQ(their_frames[i][1], 0) << where(s, i) << ": node-mavlink now keeps a byte too?";
      continue;
    }
    // Same values, same header: both must write the same bytes, CRC included.
    EXPECT_EQ(ours, their_frames[i]) << where(s, i);
  }
}

TEST(NodeMavlinkCrosscheck, AdapterMessagesFromNodeMavlinkUnpackToTheirKnownValues) {
  ASSERT_EQ(test::node_mavlink_missing(), "");
  test::ScratchDir dir;
  std::ofstream(dir.file("spec.jsonl"))
      << R"({"msgid":0,"sysid":1,"compid":1,"seq":7,"fields":{"type":2,"autopilot":12,)"
         R"("base_mode":157,"custom_mode":393216,"system_status":4,"mavlink_version":3}})" "\n"
      << R"({"msgid":77,"sysid":1,"compid":1,"seq":8,"fields":{"command":400,"result":4}})" "\n"
      << R"({"msgid":84,"sysid":1,"compid":191,"seq":9,"fields":{"time_boot_ms":123456,)"
         R"("target_system":1,"target_component":1,"coordinate_frame":1,"type_mask":3576,)"
         R"("x":10.5,"y":-4.25,"z":-3,"yaw":"NaN"}})" "\n"
      << R"({"msgid":245,"sysid":1,"compid":1,"seq":10,"fields":{"landed_state":2}})" "\n";
  NodeRun run = test::run_node_mavlink("encode '" + dir.file("spec.jsonl") + "' '" +
                                       dir.file("theirs.bin") + "'");
  ASSERT_EQ(run.exit_code, 0) << run.other_output;
  Parser parser;
  std::vector<Frame> frames = parser.feed(test::read_file(dir.file("theirs.bin")));
  ASSERT_EQ(frames.size(), 4u) << "bad CRCs: " << parser.stats().bad_crc;

  auto hb = unpack_heartbeat(frames[0].message);
  ASSERT_TRUE(hb);
  EXPECT_EQ(hb->autopilot, 12);  // MAV_AUTOPILOT_PX4
  EXPECT_EQ(hb->base_mode, 157);
  EXPECT_EQ(hb->custom_mode, 393216u);  // PX4 OFFBOARD: main mode 6 << 16
  EXPECT_EQ(hb->system_status, 4);

  auto ack = unpack_command_ack(frames[1].message);
  ASSERT_TRUE(ack);
  EXPECT_EQ(frames[1].wire_length, 3) << "extensions all zero: truncated after `result`";
  EXPECT_EQ(ack->command, 400);
  EXPECT_EQ(ack->result, 4);  // MAV_RESULT_FAILED
  EXPECT_EQ(ack->progress, 0);

  auto sp = unpack_set_position_target_local_ned(frames[2].message);
  ASSERT_TRUE(sp);
  EXPECT_EQ(frames[2].compid, 191);
  EXPECT_EQ(sp->time_boot_ms, 123456u);
  EXPECT_EQ(sp->type_mask, 3576);
  EXPECT_EQ(sp->coordinate_frame, 1);
  EXPECT_FLOAT_EQ(sp->x, 10.5f);
  EXPECT_FLOAT_EQ(sp->y, -4.25f);
  EXPECT_FLOAT_EQ(sp->z, -3.0f);
  EXPECT_TRUE(std::isnan(sp->yaw));

  auto ess = unpack_extended_sys_state(frames[3].message);
  ASSERT_TRUE(ess);
  EXPECT_EQ(ess->landed_state, 2);  // MAV_LANDED_STATE_IN_AIR
}

}  // namespace
}  // namespace eamos::mavlink
