// Every message struct survives pack -> frame -> parse -> unpack unchanged, and the field
// helpers write little-endian.
#include <gtest/gtest.h>

#include "mavlink/frame.h"
#include "mavlink/payloads.h"

namespace eamos::mavlink {
namespace {

// Encodes and parses one message, as a link would.
Message through_the_wire(const Message& m) {
  Encoder enc;
  Parser parser;
  auto frames = parser.feed(enc.encode(m));
  EXPECT_EQ(frames.size(), 1u);
  return frames.empty() ? Message{} : frames[0].message;
}

TEST(Fields, PutAndGetAreLittleEndian) {
  std::vector<uint8_t> buf(8, 0);
  put_le<uint32_t>(buf, 1, 0x11223344);
  EXPECT_EQ(buf, (std::vector<uint8_t>{0, 0x44, 0x33, 0x22, 0x11, 0, 0, 0}));
  EXPECT_EQ(get_le<uint32_t>(buf, 1), 0x11223344u);
  put_le<float>(buf, 0, 1.0f);  // 0x3F800000
  EXPECT_EQ(buf[3], 0x3F);
  put_le<double>(buf, 0, -2.5);
  EXPECT_EQ(get_le<double>(buf, 0), -2.5);
  put_le<int16_t>(buf, 0, -2);
  EXPECT_EQ(buf[0], 0xFE);
  EXPECT_EQ(get_le<int16_t>(buf, 0), -2);
}

TEST(Fields, CharArraysArePaddedAndCut) {
  MessageDef def{9, "T", wire_order({{FieldType::char_, "s", 4}}), 4, 4, 0};
  FieldWriter w(def);
  w.set_chars("s", "ab");
  Message m = w.take();
  EXPECT_EQ(m.payload, (std::vector<uint8_t>{'a', 'b', 0, 0}));
  EXPECT_EQ(FieldReader(def, m).get_chars("s"), "ab");
  FieldWriter full(def);
  full.set_chars("s", "abcdef");
  Message cut = full.take();
  EXPECT_EQ(FieldReader(def, cut).get_chars("s"), "abcd");
}

TEST(RoundTrip, Heartbeat) {
  Heartbeat in{6, 8, 0x81, 0x0A0B0C0D, 4, 3};
  auto out = unpack_heartbeat(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->type, 6);
  EXPECT_EQ(out->autopilot, 8);
  EXPECT_EQ(out->base_mode, 0x81);
  EXPECT_EQ(out->custom_mode, 0x0A0B0C0Du);
  EXPECT_EQ(out->system_status, 4);
  EXPECT_EQ(out->mavlink_version, 3);
}

TEST(RoundTrip, SysStatus) {
  SysStatus in{1, 2, 3, 500, 12600, -150, 87, 10, 2};
  auto out = unpack_sys_status(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->sensors_present, 1u);
  EXPECT_EQ(out->sensors_enabled, 2u);
  EXPECT_EQ(out->sensors_health, 3u);
  EXPECT_EQ(out->load, 500);
  EXPECT_EQ(out->voltage_battery, 12600);
  EXPECT_EQ(out->current_battery, -150);
  EXPECT_EQ(out->battery_remaining, 87);
  EXPECT_EQ(out->drop_rate_comm, 10);
  EXPECT_EQ(out->errors_comm, 2);
}

TEST(RoundTrip, LocalPositionNed) {
  LocalPositionNed in{1234, 1.5f, -2.25f, -10.0f, 0.5f, 0.25f, -0.125f};
  auto out = unpack_local_position_ned(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->time_boot_ms, 1234u);
  EXPECT_EQ(out->x, 1.5f);
  EXPECT_EQ(out->y, -2.25f);
  EXPECT_EQ(out->z, -10.0f);
  EXPECT_EQ(out->vx, 0.5f);
  EXPECT_EQ(out->vy, 0.25f);
  EXPECT_EQ(out->vz, -0.125f);
}

TEST(RoundTrip, GlobalPositionInt) {
  GlobalPositionInt in{99, 473977418, 85455939, 488000, 10000, -5, 6, -7, 35999};
  auto out = unpack_global_position_int(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->time_boot_ms, 99u);
  EXPECT_EQ(out->lat, 473977418);
  EXPECT_EQ(out->lon, 85455939);
  EXPECT_EQ(out->alt, 488000);
  EXPECT_EQ(out->relative_alt, 10000);
  EXPECT_EQ(out->vx, -5);
  EXPECT_EQ(out->vy, 6);
  EXPECT_EQ(out->vz, -7);
  EXPECT_EQ(out->hdg, 35999);
}

TEST(RoundTrip, HilStateQuaternionKeepsTheTrueAttitudePositionAndVelocity) {
  HilStateQuaternion in{1234567890123, {0.5f, -0.5f, 0.25f, -0.75f}, 473977418, -85455939, 498000, -250, 310, -12};
  auto out = unpack_hil_state_quaternion(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->time_usec, 1234567890123u);
  EXPECT_EQ(out->attitude_quaternion, in.attitude_quaternion);
  EXPECT_EQ(out->lat, 473977418);
  EXPECT_EQ(out->lon, -85455939);
  EXPECT_EQ(out->alt, 498000);
  EXPECT_EQ(out->vx, -250);
  EXPECT_EQ(out->vy, 310);
  EXPECT_EQ(out->vz, -12);
}

TEST(RoundTrip, AttitudeKeepsTimeAndAngles) {
  Attitude in{4321, 0.125f, -0.25f, 3.0f};
  auto out = unpack_attitude(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->time_boot_ms, 4321u);
  EXPECT_EQ(out->roll, 0.125f);
  EXPECT_EQ(out->pitch, -0.25f);
  EXPECT_EQ(out->yaw, 3.0f);
}

TEST(RoundTrip, CommandLong) {
  CommandLong in{1, 1, 400, 2, {1, 21196, 0, 0, 0, 0, 7.5f}};
  auto out = unpack_command_long(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->target_system, 1);
  EXPECT_EQ(out->target_component, 1);
  EXPECT_EQ(out->command, 400);
  EXPECT_EQ(out->confirmation, 2);
  EXPECT_EQ(out->param, in.param);
}

TEST(RoundTrip, CommandInt) {
  CommandInt in{1, 1, 6, 192, 0, 1, {-1, 1, 0, 3}, 473977418, 85455939, 25.5f};
  auto out = unpack_command_int(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->target_system, 1);
  EXPECT_EQ(out->target_component, 1);
  EXPECT_EQ(out->frame, 6);
  EXPECT_EQ(out->command, 192);
  EXPECT_EQ(out->current, 0);
  EXPECT_EQ(out->autocontinue, 1);
  EXPECT_EQ(out->param, in.param);
  EXPECT_EQ(out->x, 473977418);
  EXPECT_EQ(out->y, 85455939);
  EXPECT_EQ(out->z, 25.5f);
}

TEST(RoundTrip, MissionItemIntKeepsEveryFieldAndTheFenceType) {
  MissionItemInt in{1, 1, 3, 0, 5001, 0, 1, {4, 0, 0, 0}, -353632620, 1491652370, 0.0f, mission_type::FENCE};
  auto out = unpack_mission_item_int(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->target_system, 1);
  EXPECT_EQ(out->seq, 3);
  EXPECT_EQ(out->frame, 0);
  EXPECT_EQ(out->command, 5001);
  EXPECT_EQ(out->autocontinue, 1);
  EXPECT_EQ(out->param, in.param);
  EXPECT_EQ(out->x, -353632620);
  EXPECT_EQ(out->y, 1491652370);
  EXPECT_EQ(out->mission_type, mission_type::FENCE);
}

TEST(RoundTrip, MissionCountAckAndRequestListKeepTheMissionType) {
  auto count = unpack_mission_count(through_the_wire(pack(MissionCount{1, 1, 7, mission_type::FENCE, 42})));
  ASSERT_TRUE(count);
  EXPECT_EQ(count->count, 7);
  EXPECT_EQ(count->mission_type, mission_type::FENCE);
  EXPECT_EQ(count->opaque_id, 42u);
  auto ack = unpack_mission_ack(through_the_wire(pack(MissionAck{255, 190, mission_result::NO_SPACE, mission_type::FENCE})));
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->target_system, 255);
  EXPECT_EQ(ack->target_component, 190);
  EXPECT_EQ(ack->type, mission_result::NO_SPACE);
  EXPECT_EQ(ack->mission_type, mission_type::FENCE);
  auto list = unpack_mission_request_list(through_the_wire(pack(MissionRequestList{1, 1, mission_type::FENCE})));
  ASSERT_TRUE(list);
  EXPECT_EQ(list->mission_type, mission_type::FENCE);
}

TEST(RoundTrip, MissionRequestIsReadFromEitherTheIntOrTheLegacyMessage) {
  Message modern = pack(MissionRequest{1, 191, 9, mission_type::FENCE, false});
  Message legacy = pack(MissionRequest{1, 191, 9, mission_type::FENCE, true});
  EXPECT_EQ(modern.id, msg::MISSION_REQUEST_INT);
  EXPECT_EQ(legacy.id, msg::MISSION_REQUEST);
  for (const Message& m : {modern, legacy}) {
    auto out = unpack_mission_request(through_the_wire(m));
    ASSERT_TRUE(out);
    EXPECT_EQ(out->target_component, 191);
    EXPECT_EQ(out->seq, 9);
    EXPECT_EQ(out->mission_type, mission_type::FENCE);
    EXPECT_EQ(out->legacy, m.id == msg::MISSION_REQUEST);
  }
}

TEST(RoundTrip, CommandAck) {
  CommandAck in{176, 5, 50, -3, 255, 190};
  auto out = unpack_command_ack(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->command, 176);
  EXPECT_EQ(out->result, 5);
  EXPECT_EQ(out->progress, 50);
  EXPECT_EQ(out->result_param2, -3);
  EXPECT_EQ(out->target_system, 255);
  EXPECT_EQ(out->target_component, 190);
}

TEST(RoundTrip, SetPositionTargetLocalNed) {
  SetPositionTargetLocalNed in{10, 2, 1, 1, 0x0DF8, 1, 2, -3, 4, 5, 6, 7, 8, 9, 1.25f, 0.5f};
  auto out = unpack_set_position_target_local_ned(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->time_boot_ms, 10u);
  EXPECT_EQ(out->target_system, 2);
  EXPECT_EQ(out->target_component, 1);
  EXPECT_EQ(out->coordinate_frame, 1);
  EXPECT_EQ(out->type_mask, 0x0DF8);
  EXPECT_EQ(out->x, 1);
  EXPECT_EQ(out->y, 2);
  EXPECT_EQ(out->z, -3);
  EXPECT_EQ(out->vx, 4);
  EXPECT_EQ(out->vy, 5);
  EXPECT_EQ(out->vz, 6);
  EXPECT_EQ(out->afx, 7);
  EXPECT_EQ(out->afy, 8);
  EXPECT_EQ(out->afz, 9);
  EXPECT_EQ(out->yaw, 1.25f);
  EXPECT_EQ(out->yaw_rate, 0.5f);
}

TEST(RoundTrip, ExtendedSysState) {
  auto out = unpack_extended_sys_state(through_the_wire(pack(ExtendedSysState{3, 2})));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->vtol_state, 3);
  EXPECT_EQ(out->landed_state, 2);
}

TEST(RoundTrip, BatteryStatus) {
  BatteryStatus in;
  in.id = 1;
  in.battery_function = 1;
  in.type = 1;
  in.temperature = 2500;
  for (int i = 0; i < 10; ++i) in.voltages[i] = static_cast<uint16_t>(i < 4 ? 4100 + i : 65535);
  in.current_battery = 1234;
  in.current_consumed = 560;
  in.energy_consumed = 7890;
  in.battery_remaining = 66;
  in.time_remaining = 600;
  in.charge_state = 1;
  auto out = unpack_battery_status(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->id, 1);
  EXPECT_EQ(out->battery_function, 1);
  EXPECT_EQ(out->type, 1);
  EXPECT_EQ(out->temperature, 2500);
  EXPECT_EQ(out->voltages, in.voltages);
  EXPECT_EQ(out->current_battery, 1234);
  EXPECT_EQ(out->current_consumed, 560);
  EXPECT_EQ(out->energy_consumed, 7890);
  EXPECT_EQ(out->battery_remaining, 66);
  EXPECT_EQ(out->time_remaining, 600);
  EXPECT_EQ(out->charge_state, 1);
}

TEST(Unpack, OtherMessageIdGivesNothing) {
  EXPECT_FALSE(unpack_command_ack(pack(Heartbeat{})));
  EXPECT_FALSE(unpack_heartbeat(pack(CommandAck{})));
}

}  // namespace
}  // namespace eamos::mavlink

namespace eamos::mavlink {
namespace {

TEST(RoundTrip, StatustextKeepsSeverityTextAndChunk) {
  Statustext in{3, "PreArm: Need Position Estimate", 7, 1};
  auto out = unpack_statustext(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->severity, 3);
  EXPECT_EQ(out->text, "PreArm: Need Position Estimate");
  EXPECT_EQ(out->id, 7);
  EXPECT_EQ(out->chunk_seq, 1);
}

// A full 50-character text has no NUL on the wire; bytes outside printable ASCII (which
// would be invalid UTF-8 in a JSON trace) arrive as '?'.
TEST(RoundTrip, StatustextOfFiftyCharactersAndForeignBytesIsReadSafely) {
  std::string fifty(50, 'a');
  fifty[10] = '\xff';
  fifty[20] = '\x01';
  auto out = unpack_statustext(through_the_wire(pack(Statustext{6, fifty, 0, 0})));
  ASSERT_TRUE(out);
  ASSERT_EQ(out->text.size(), 50u);
  EXPECT_EQ(out->text[10], '?');
  EXPECT_EQ(out->text[20], '?');
  EXPECT_EQ(out->text[49], 'a');
  EXPECT_TRUE(out->full);
}

// A chunk that fills its field may end on the blank between two words of a longer text: kept.
TEST(RoundTrip, AFullStatustextChunkKeepsItsLastBlank) {
  std::string chunk = std::string(49, 'a') + " ";
  auto out = unpack_statustext(through_the_wire(pack(Statustext{4, chunk, 3, 0})));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->text, chunk);
  EXPECT_TRUE(out->full);
  auto last = unpack_statustext(through_the_wire(pack(Statustext{4, "end \n", 3, 1})));
  ASSERT_TRUE(last);
  EXPECT_EQ(last->text, "end");
  EXPECT_FALSE(last->full);
}

}  // namespace
}  // namespace eamos::mavlink

namespace eamos::mavlink {
namespace {

// PX4 sends "Armed by external command\n": the newline is no part of the text.
TEST(RoundTrip, StatustextDropsATrailingNewline) {
  auto out = unpack_statustext(through_the_wire(pack(Statustext{6, "Armed by external command\n", 0, 0})));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->text, "Armed by external command");
  // Also when the newline fills the chunk's 50th character: no '?' at the end.
  auto full = unpack_statustext(through_the_wire(pack(Statustext{6, std::string(49, 'b') + "\n", 0, 0})));
  ASSERT_TRUE(full);
  EXPECT_EQ(full->text, std::string(49, 'b'));
  EXPECT_TRUE(full->full);
}

TEST(RoundTrip, ParamRequestReadKeepsTargetNameAndIndex) {
  auto out = unpack_param_request_read(through_the_wire(pack(ParamRequestRead{3, 1, "WPNAV_SPEED_UP", -1})));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->target_system, 3);
  EXPECT_EQ(out->target_component, 1);
  EXPECT_EQ(out->param_id, "WPNAV_SPEED_UP");
  EXPECT_EQ(out->param_index, -1);
}

// A name of exactly 16 characters has no NUL on the wire.
TEST(RoundTrip, ParamValueOfASixteenCharacterNameKeepsEveryField) {
  ParamValue in{"MPC_Z_VEL_MAX_DN", 1.25f, param_type::REAL32, 1234, 567};
  ASSERT_EQ(in.param_id.size(), 16u);
  auto out = unpack_param_value(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->param_id, "MPC_Z_VEL_MAX_DN");
  EXPECT_EQ(out->param_value, 1.25f);
  EXPECT_EQ(out->param_type, param_type::REAL32);
  EXPECT_EQ(out->param_count, 1234);
  EXPECT_EQ(out->param_index, 567);
}

TEST(RoundTrip, ParamValueNameWithForeignBytesArrivesAsQuestionMarks) {
  auto out = unpack_param_value(through_the_wire(pack(ParamValue{"LAND\x01SPEED\xff", 50, param_type::REAL32, 1, 0})));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->param_id, "LAND?SPEED?");
}

TEST(RoundTrip, ParamSetKeepsTargetNameValueAndType) {
  auto out = unpack_param_set(through_the_wire(pack(ParamSet{2, 1, "DISARM_DELAY", 0, param_type::INT8})));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->target_system, 2);
  EXPECT_EQ(out->param_id, "DISARM_DELAY");
  EXPECT_EQ(out->param_value, 0.0f);
  EXPECT_EQ(out->param_type, param_type::INT8);
  EXPECT_FALSE(unpack_param_set(pack(ParamValue{})));
}

}  // namespace
}  // namespace eamos::mavlink

namespace eamos::mavlink {
namespace {

TEST(RoundTrip, CameraTriggerKeepsTimeAndSequence) {
  auto out = unpack_camera_trigger(through_the_wire(pack(CameraTrigger{123456789012ULL, 70000})));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->time_usec, 123456789012ULL);
  EXPECT_EQ(out->seq, 70000u);
}

TEST(RoundTrip, CameraFeedbackKeepsEveryField) {
  CameraFeedback in{987654321, 1, 2, 513, 473977420, 85455940, 488.5f, 20.25f, 1.5f, -2.5f, 270.0f, 35.0f, 1, 9};
  auto out = unpack_camera_feedback(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->time_usec, 987654321u);
  EXPECT_EQ(out->target_system, 1);
  EXPECT_EQ(out->cam_idx, 2);
  EXPECT_EQ(out->img_idx, 513);
  EXPECT_EQ(out->lat, 473977420);
  EXPECT_EQ(out->lng, 85455940);
  EXPECT_EQ(out->alt_msl, 488.5f);
  EXPECT_EQ(out->alt_rel, 20.25f);
  EXPECT_EQ(out->roll, 1.5f);
  EXPECT_EQ(out->pitch, -2.5f);
  EXPECT_EQ(out->yaw, 270.0f);
  EXPECT_EQ(out->foc_len, 35.0f);
  EXPECT_EQ(out->flags, 1);
  EXPECT_EQ(out->completed_captures, 9);
}

TEST(RoundTrip, CameraImageCapturedKeepsEveryFieldAndAFailedCapture) {
  CameraImageCaptured in;
  in.time_boot_ms = 61000;
  in.time_utc = 1700000000000000ULL;
  in.camera_id = 1;
  in.lat = -338688197;
  in.lon = 1512092955;
  in.alt = 58000;
  in.relative_alt = 12000;
  in.q = {0.5f, 0.5f, -0.5f, 0.5f};
  in.image_index = -1;
  in.capture_result = 0;
  in.file_url = "file:///images/IMG_0001.jpg";
  auto out = unpack_camera_image_captured(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->time_boot_ms, 61000u);
  EXPECT_EQ(out->time_utc, 1700000000000000ULL);
  EXPECT_EQ(out->camera_id, 1);
  EXPECT_EQ(out->lat, -338688197);
  EXPECT_EQ(out->lon, 1512092955);
  EXPECT_EQ(out->alt, 58000);
  EXPECT_EQ(out->relative_alt, 12000);
  EXPECT_EQ(out->q, in.q);
  EXPECT_EQ(out->image_index, -1);
  EXPECT_EQ(out->capture_result, 0);
  EXPECT_EQ(out->file_url, in.file_url);
}

TEST(RoundTrip, CameraImageCapturedFileUrlWithForeignBytesArrivesAsQuestionMarks) {
  CameraImageCaptured in;
  in.file_url = std::string("a\n\xff") + "b";
  auto out = unpack_camera_image_captured(through_the_wire(pack(in)));
  ASSERT_TRUE(out);
  EXPECT_EQ(out->file_url, "a??b");
}

TEST(RoundTrip, CameraCaptureIsReadFromEachOfTheThreeConfirmations) {
  for (uint32_t id : {msg::CAMERA_TRIGGER, msg::CAMERA_FEEDBACK, msg::CAMERA_IMAGE_CAPTURED}) {
    auto out = unpack_camera_capture(through_the_wire(pack(CameraCapture{id, 42, true})));
    ASSERT_TRUE(out) << id;
    EXPECT_EQ(out->message_id, id);
    EXPECT_EQ(out->image_index, 42);
    EXPECT_TRUE(out->captured);
  }
  auto failed = unpack_camera_capture(through_the_wire(pack(CameraCapture{msg::CAMERA_IMAGE_CAPTURED, 7, false})));
  ASSERT_TRUE(failed);
  EXPECT_FALSE(failed->captured);
  EXPECT_EQ(failed->image_index, 7);
  EXPECT_FALSE(unpack_camera_capture(pack(Heartbeat{})));
  EXPECT_FALSE(unpack_camera_trigger(pack(CameraFeedback{})));
}

}  // namespace
}  // namespace eamos::mavlink
