// PARAM_SET and the fence's mission protocol, as an autopilot with a polygon fence answers
// them (ArduPilot's MissionItemProtocol_Fence, PX4's MavlinkMissionManager): it asks for each
// corner in turn, keeps the list once the last one came, and gives it back when asked.
#include <cstring>

#include "mavlink/enums.h"
#include "sim_vehicle/sim_vehicle.h"

namespace eamos::sim_vehicle {

namespace ml = eamos::mavlink;

bool SimVehicle::on_fence_frame(const ml::Frame& frame) {
  const ml::Message& m = frame.message;
  if (auto p = ml::unpack_param_set(m)) {
    on_param_set(*p);
    return true;
  }
  if (options_.fence_capacity <= 0) return false;  // no fence: nothing answers
  auto ours = [&](uint8_t target, uint8_t type) {
    return (target == options_.sysid || target == 0) && type == ml::mission_type::FENCE;
  };
  if (auto c = ml::unpack_mission_count(m); c && ours(c->target_system, c->mission_type)) {
    on_fence_count(frame, *c);
    return true;
  }
  if (auto item = ml::unpack_mission_item_int(m); item && ours(item->target_system, item->mission_type)) {
    on_fence_item(frame, *item);
    return true;
  }
  if (auto l = ml::unpack_mission_request_list(m); l && ours(l->target_system, l->mission_type)) {
    send(ml::pack(ml::MissionCount{frame.sysid, frame.compid, static_cast<uint16_t>(fence_.size()),
                                   ml::mission_type::FENCE}));
    return true;
  }
  if (auto r = ml::unpack_mission_request(m); r && ours(r->target_system, r->mission_type)) {
    if (r->seq >= fence_.size()) return true;
    ml::MissionItemInt item = fence_[r->seq];
    item.target_system = frame.sysid;
    item.target_component = frame.compid;
    item.x += options_.fence_read_back_shift_e7;
    send(ml::pack(item));
    return true;
  }
  return ml::unpack_mission_ack(m).has_value();  // the end of a read back: nothing to do
}

void SimVehicle::on_fence_count(const ml::Frame& frame, const ml::MissionCount& c) {
  if (++fence_counts_seen_ <= options_.fence_counts_ignored) return;
  if (c.count > options_.fence_capacity) {
    send(ml::pack(ml::MissionAck{frame.sysid, frame.compid, ml::mission_result::NO_SPACE, ml::mission_type::FENCE}));
    return;
  }
  incoming_.assign(c.count, {});
  incoming_next_ = 0;
  if (c.count == 0) {
    fence_.clear();
    send(ml::pack(ml::MissionAck{frame.sysid, frame.compid, ml::mission_result::ACCEPTED, ml::mission_type::FENCE}));
    return;
  }
  request_fence_item(frame, 0);
}

void SimVehicle::on_fence_item(const ml::Frame& frame, const ml::MissionItemInt& item) {
  if (item.seq != incoming_next_ || item.seq >= incoming_.size()) return;  // a resend of one already taken
  if (item.command != ml::cmd::NAV_FENCE_POLYGON_VERTEX_INCLUSION) {
    send(ml::pack(ml::MissionAck{frame.sysid, frame.compid, ml::mission_result::UNSUPPORTED, ml::mission_type::FENCE}));
    return;
  }
  incoming_[incoming_next_++] = item;
  if (incoming_next_ < incoming_.size()) return request_fence_item(frame, incoming_next_);
  fence_ = incoming_;
  send(ml::pack(ml::MissionAck{frame.sysid, frame.compid, ml::mission_result::ACCEPTED, ml::mission_type::FENCE}));
}

// ArduPilot may ask with the older MISSION_REQUEST, PX4 with MISSION_REQUEST_INT.
void SimVehicle::request_fence_item(const ml::Frame& frame, uint16_t seq) {
  ++fence_requests_;
  bool legacy = dialect_.mav_autopilot != ml::autopilot::PX4;
  send(ml::pack(ml::MissionRequest{frame.sysid, frame.compid, seq, ml::mission_type::FENCE, legacy}));
}

void SimVehicle::on_param_set(const ml::ParamSet& p) {
  if (p.target_system != options_.sysid && p.target_system != 0) return;
  ml::ParamSet kept = p;
  if (options_.read_only_params.contains(p.param_id)) {
    auto it = params_set_.find(p.param_id);
    kept.param_value = it == params_set_.end() ? 0.0f : it->second.param_value;
  } else {
    params_set_[p.param_id] = p;
  }
  send(ml::pack(ml::ParamValue{kept.param_id, kept.param_value, kept.param_type, 0, 0}));
}

std::optional<double> SimVehicle::param(const std::string& name) const {
  auto it = params_set_.find(name);
  if (it == params_set_.end()) return std::nullopt;
  const ml::ParamSet& p = it->second;
  bool bytewise = dialect_.mav_autopilot == ml::autopilot::PX4 && p.param_type != ml::param_type::REAL32;
  if (!bytewise) return p.param_value;
  int32_t i = 0;
  std::memcpy(&i, &p.param_value, sizeof i);
  return i;
}

}  // namespace eamos::sim_vehicle
