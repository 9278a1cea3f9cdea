#include "mavlink_adapter/fence_upload.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "diag/number.h"
#include "mavlink/enums.h"
#include "mavlink_adapter/telemetry.h"

namespace eamos::mavlink_adapter {

using diag::number_text;

namespace ml = eamos::mavlink;

namespace {

constexpr uint8_t kFrameGlobal = 0;  // MAV_FRAME_GLOBAL: x, y in degE7 for MISSION_ITEM_INT

bool is_px4(const Autopilot& a) { return a.mav_autopilot == ml::autopilot::PX4; }

// What a breach makes the autopilot do, as the drone's failsafe would: ArduPilot FENCE_ACTION
// (1 RTL or land, 2 land, 4 brake or land), PX4 GF_ACTION (2 hold, 3 return, 5 land).
float breach_action(const Autopilot& a, fleet::Failsafe f) {
  switch (f) {
    case fleet::Failsafe::land: return is_px4(a) ? 5.0f : 2.0f;
    case fleet::Failsafe::return_home: return is_px4(a) ? 3.0f : 1.0f;
    case fleet::Failsafe::hover: return is_px4(a) ? 2.0f : 4.0f;
  }
  return is_px4(a) ? 5.0f : 2.0f;
}

std::vector<FenceParam> fence_params(const Autopilot& a, const fleet::Geofence& g, double home_z,
                                     fleet::Failsafe failsafe) {
  std::vector<FenceParam> out;
  std::optional<float> ceiling;
  if (g.max_altitude_m) ceiling = static_cast<float>(*g.max_altitude_m - home_z);
  if (is_px4(a)) {
    if (ceiling) out.push_back({"GF_MAX_VER_DIST", *ceiling, false});
    out.push_back({"GF_ACTION", breach_action(a, failsafe), true});
    return out;
  }
  // FENCE_TYPE bits: 1 maximum altitude, 4 polygon.
  out.push_back({"FENCE_TYPE", ceiling ? 5.0f : 4.0f, true});
  if (ceiling) out.push_back({"FENCE_ALT_MAX", *ceiling, false});
  out.push_back({"FENCE_ACTION", breach_action(a, failsafe), true});
  out.push_back({"FENCE_ENABLE", 1.0f, true});
  return out;
}

// The value a PARAM_SET carries, and how the autopilot's PARAM_VALUE is read back: PX4 copies
// an integer's bytes into the float (bytewise), ArduPilot converts it to a float.
float encode(const Autopilot& a, const FenceParam& p) {
  if (!p.integer || !is_px4(a)) return p.value;
  int32_t i = static_cast<int32_t>(std::lround(p.value));
  float f = 0;
  std::memcpy(&f, &i, sizeof f);
  return f;
}

double decode(const Autopilot& a, const FenceParam& p, float wire) {
  if (!p.integer || !is_px4(a)) return wire;
  int32_t i = 0;
  std::memcpy(&i, &wire, sizeof i);
  return i;
}

std::string degrees(int32_t e7) {
  char text[32];
  std::snprintf(text, sizeof text, "%.7f", e7 / 1e7);
  return text;
}

}  // namespace

AutopilotFence autopilot_fence(const Autopilot& a, const fleet::Geofence& g, fleet::Vec3 home,
                               fleet::Failsafe failsafe, GlobalOrigin origin, uint8_t sysid) {
  AutopilotFence out;
  const auto n = static_cast<uint16_t>(g.polygon.size());
  for (uint16_t i = 0; i < n; ++i) {
    const auto& [x, y] = g.polygon[i];
    fleet::Vec3 ned = mission_to_ned({x, y, home.z}, home);
    ml::MissionItemInt item;
    item.target_system = sysid;
    item.target_component = ml::comp::AUTOPILOT1;
    item.seq = i;
    item.frame = kFrameGlobal;
    item.command = ml::cmd::NAV_FENCE_POLYGON_VERTEX_INCLUSION;
    item.autocontinue = 1;
    item.param[0] = static_cast<float>(n);
    std::tie(item.x, item.y) = offset_lat_lon(origin.lat_e7, origin.lon_e7, ned.x, ned.y);
    item.mission_type = ml::mission_type::FENCE;
    out.items.push_back(item);
  }
  out.params = fence_params(a, g, home.z, failsafe);
  return out;
}

std::string compare_fence(const std::vector<ml::MissionItemInt>& sent, const std::vector<ml::MissionItemInt>& read) {
  if (sent.size() != read.size())
    return "it holds " + std::to_string(read.size()) + " fence item(s), " + std::to_string(sent.size()) + " were sent";
  for (std::size_t i = 0; i < sent.size(); ++i) {
    const ml::MissionItemInt& s = sent[i];
    const ml::MissionItemInt& r = read[i];
    std::string which = "fence item " + std::to_string(i);
    if (r.command != s.command)
      return which + " is command " + std::to_string(r.command) + ", " + std::to_string(s.command) + " was sent";
    if (std::lround(r.param[0]) != std::lround(s.param[0]))
      return which + " says the polygon has " + number_text(r.param[0]) + " corners, " + number_text(s.param[0]) +
             " was sent";
    if (std::abs(int64_t{r.x} - s.x) > 1 || std::abs(int64_t{r.y} - s.y) > 1)
      return which + " lies at (" + degrees(r.x) + ", " + degrees(r.y) + "), (" + degrees(s.x) + ", " +
             degrees(s.y) + ") was sent";
  }
  return "";
}

std::string mission_result_text(uint8_t result) {
  switch (result) {
    case ml::mission_result::ACCEPTED: return "accepted";
    case ml::mission_result::ERROR: return "MAV_MISSION_ERROR (a generic error)";
    case ml::mission_result::UNSUPPORTED: return "MAV_MISSION_UNSUPPORTED (it has no such fence)";
    case ml::mission_result::NO_SPACE: return "MAV_MISSION_NO_SPACE (too many corners for its fence storage)";
    case ml::mission_result::INVALID: return "MAV_MISSION_INVALID (a corner it will not take)";
    case ml::mission_result::INVALID_SEQUENCE: return "MAV_MISSION_INVALID_SEQUENCE";
    case ml::mission_result::DENIED: return "MAV_MISSION_DENIED (not accepting a fence now)";
    case ml::mission_result::OPERATION_CANCELLED: return "MAV_MISSION_OPERATION_CANCELLED";
  }
  return "MAV_MISSION_RESULT " + std::to_string(result);
}

FenceUpload::FenceUpload(mid::EventLoop& loop, const Autopilot& autopilot, Hooks hooks, Options options)
    : loop_(loop), autopilot_(autopilot), hooks_(std::move(hooks)), options_(options) {}

FenceUpload::~FenceUpload() { loop_.cancel(timer_); }

void FenceUpload::start(AutopilotFence fence, uint8_t sysid, Done done) {
  fence_ = std::move(fence);
  sysid_ = sysid;
  done_ = std::move(done);
  phase_ = Phase::upload;
  const auto n = static_cast<uint16_t>(fence_.items.size());
  expect(ml::pack(ml::MissionCount{sysid_, ml::comp::AUTOPILOT1, n, ml::mission_type::FENCE}),
         "its request for the first fence corner (MISSION_REQUEST_INT) after MISSION_COUNT");
}

void FenceUpload::on_message(const ml::Message& m) {
  if (phase_ == Phase::idle || phase_ == Phase::done) return;
  if (auto r = ml::unpack_mission_request(m); r && r->mission_type == ml::mission_type::FENCE) return on_request(*r);
  if (auto a = ml::unpack_mission_ack(m); a && a->mission_type == ml::mission_type::FENCE) return on_ack(*a);
  if (auto c = ml::unpack_mission_count(m); c && c->mission_type == ml::mission_type::FENCE) return on_count(*c);
  if (auto i = ml::unpack_mission_item_int(m); i && i->mission_type == ml::mission_type::FENCE) return on_item(*i);
  if (auto v = ml::unpack_param_value(m)) return on_param(*v);
}

void FenceUpload::on_request(const ml::MissionRequest& r) {
  if (phase_ != Phase::upload) return;
  if (r.seq >= fence_.items.size())
    return finish("the autopilot asked for fence item " + std::to_string(r.seq) + " of " +
                  std::to_string(fence_.items.size()));
  // The last corner is answered by the ACK; any other by the request for the next one.
  bool last = r.seq + 1u == fence_.items.size();
  expect(ml::pack(addressed(fence_.items[r.seq])),
         last ? std::string("its MISSION_ACK of the fence")
              : "its request for fence item " + std::to_string(r.seq + 1));
}

void FenceUpload::on_ack(const ml::MissionAck& a) {
  if (phase_ != Phase::upload) return;
  if (a.type != ml::mission_result::ACCEPTED)
    return finish(std::string(autopilot_.name) + " refused the fence: " + mission_result_text(a.type));
  hooks_.note("fence of " + std::to_string(fence_.items.size()) + " corners uploaded to " + autopilot_.name +
              "; reading it back");
  read_back();
}

void FenceUpload::read_back() {
  phase_ = Phase::read_count;
  read_.clear();
  expect(ml::pack(ml::MissionRequestList{sysid_, ml::comp::AUTOPILOT1, ml::mission_type::FENCE}),
         "its MISSION_COUNT of the fence after MISSION_REQUEST_LIST");
}

void FenceUpload::on_count(const ml::MissionCount& c) {
  if (phase_ != Phase::read_count) return;
  read_count_ = c.count;
  if (c.count != fence_.items.size()) return finish("the fence read back from " + std::string(autopilot_.name) +
                                                    " differs: " + compare_fence(fence_.items, std::vector<ml::MissionItemInt>(c.count)));
  phase_ = Phase::read_items;
  request_item(0);
}

void FenceUpload::request_item(uint16_t seq) {
  expect(ml::pack(ml::MissionRequest{sysid_, ml::comp::AUTOPILOT1, seq, ml::mission_type::FENCE}),
         "fence item " + std::to_string(seq) + " (MISSION_ITEM_INT) it was asked for");
}

void FenceUpload::on_item(const ml::MissionItemInt& item) {
  if (phase_ != Phase::read_items || item.seq != read_.size()) return;  // a resend's answer twice
  read_.push_back(item);
  if (read_.size() < read_count_) return request_item(static_cast<uint16_t>(read_.size()));
  loop_.cancel(timer_);
  hooks_.send(ml::pack(ml::MissionAck{sysid_, ml::comp::AUTOPILOT1, ml::mission_result::ACCEPTED,
                                      ml::mission_type::FENCE}));
  if (std::string diff = compare_fence(fence_.items, read_); !diff.empty())
    return finish("the fence read back from " + std::string(autopilot_.name) + " differs: " + diff);
  phase_ = Phase::params;
  param_ = 0;
  set_param();
}

void FenceUpload::set_param() {
  if (param_ >= fence_.params.size()) {
    std::string set;
    for (const FenceParam& p : fence_.params) set += (set.empty() ? "" : ", ") + p.name + " " + number_text(p.value);
    hooks_.note(std::string(autopilot_.name) + " holds the fence itself (" + set + ")");
    return finish("");
  }
  const FenceParam& p = fence_.params[param_];
  uint8_t type = p.integer ? (is_px4(autopilot_) ? ml::param_type::INT32 : ml::param_type::INT8) : ml::param_type::REAL32;
  expect(ml::pack(ml::ParamSet{sysid_, ml::comp::AUTOPILOT1, p.name, encode(autopilot_, p), type}),
         "its PARAM_VALUE of " + p.name + " after PARAM_SET");
}

void FenceUpload::on_param(const ml::ParamValue& v) {
  if (phase_ != Phase::params || param_ >= fence_.params.size() || v.param_id != fence_.params[param_].name) return;
  const FenceParam& p = fence_.params[param_];
  double took = decode(autopilot_, p, v.param_value);
  if (std::abs(took - p.value) > 1e-3 * std::max(1.0, std::abs(double{p.value})))
    return finish(std::string(autopilot_.name) + " kept " + p.name + " at " + number_text(took) + " when set to " +
                  number_text(p.value) + "; is the parameter read-only or out of its range on this firmware?");
  ++param_;
  set_param();
}

void FenceUpload::expect(ml::Message m, std::string waiting_for) {
  loop_.cancel(timer_);
  pending_ = std::move(m);
  waiting_for_ = std::move(waiting_for);
  sends_ = 0;
  resend();
}

void FenceUpload::resend() {
  if (sends_ >= options_.attempts) {
    char text[96];
    std::snprintf(text, sizeof text, " in %d tries %g s apart", options_.attempts, options_.reply_timeout_s);
    return finish(std::string(autopilot_.name) + " never sent " + waiting_for_ + text +
                  "; does its firmware keep a polygon fence (ArduPilot 4.0+, PX4 1.10+)?");
  }
  ++sends_;
  hooks_.send(pending_);
  timer_ = loop_.after(options_.reply_timeout_s, [this] { resend(); });
}

void FenceUpload::finish(const std::string& error) {
  loop_.cancel(timer_);
  timer_ = mid::kNoTimer;
  phase_ = Phase::done;
  error_ = error;
  if (done_) {
    Done done = std::move(done_);
    done_ = nullptr;
    done(error);
  }
}

ml::MissionItemInt FenceUpload::addressed(ml::MissionItemInt item) const {
  item.target_system = sysid_;
  item.target_component = ml::comp::AUTOPILOT1;
  return item;
}

}  // namespace eamos::mavlink_adapter
