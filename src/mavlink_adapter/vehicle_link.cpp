#include "mavlink_adapter/vehicle_link.h"

#include "mid/site_limits.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <map>
#include <optional>

#include "diag/log.h"
#include "mavlink/enums.h"

namespace eamos::mavlink_adapter {

namespace ml = eamos::mavlink;

/// The first autopilot HEARTBEAT and the parameters read at connect, handed from the link's
/// thread to connect().
struct FirstHeartbeat {
  std::mutex mutex;
  std::condition_variable cv;
  bool heard = false;
  bool signed_heard = false;  ///< a HEARTBEAT with a verified signature came
  uint8_t sysid = 0;
  uint8_t autopilot = 0;
  std::map<std::string, float> params;  ///< PARAM_VALUE of the autopilot, by name
};

namespace {

/// The link id of our signed frames: one link per drone, so any fixed value serves.
constexpr uint8_t kSigningLinkId = 1;

/// Reads `params` by name, asking again every half second for those missing, for at most
/// `timeout_s` wall seconds; blocking like the wait for the HEARTBEAT (`lock` holds
/// `first`'s mutex). What did not come is missing from the result.
std::map<std::string, float> read_params(FirstHeartbeat& first, std::unique_lock<std::mutex>& lock,
                                         const std::vector<LimitParam>& params, double timeout_s,
                                         const std::function<void(const char*)>& request) {
  auto all_read = [&] {
    for (const LimitParam& p : params)
      if (!first.params.contains(p.name)) return false;
    return true;
  };
  using clock = std::chrono::steady_clock;
  auto deadline = clock::now() + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(timeout_s));
  while (!all_read() && clock::now() < deadline) {
    std::vector<const char*> missing;
    for (const LimitParam& p : params)
      if (!first.params.contains(p.name)) missing.push_back(p.name);
    lock.unlock();  // the link's thread fills `first` meanwhile
    for (const char* name : missing) request(name);
    lock.lock();
    first.cv.wait_until(lock, std::min(deadline, clock::now() + std::chrono::milliseconds(500)), all_read);
  }
  return first.params;
}

}  // namespace

VehicleLink::VehicleLink(const fleet::DroneSettings& settings, mid::EventLoop& loop, const MavlinkOptions& options,
                         FrameHandler on_frame, Note note)
    : settings_(settings), loop_(loop), options_(options), on_frame_(std::move(on_frame)), note_(std::move(note)) {}

VehicleLink::~VehicleLink() {
  close();
  loop_.cancel(heartbeat_timer_);
}

void VehicleLink::close() {
  if (link_ && link_->foreign_datagrams() > 0)
    diag::Logger{"mavlink", settings_.name}.warning(std::to_string(link_->foreign_datagrams()) +
                                                    " datagram(s) from other addresses than the vehicle's were ignored in all");
  link_.reset();  // joins the receive thread: nothing new gets posted
}

std::function<void(ml::Frame)> VehicleLink::receiver(std::shared_ptr<FirstHeartbeat> first, uint8_t wanted) {
  std::weak_ptr<bool> alive = alive_;
  mid::EventLoop* loop = &loop_;
  return [this, first, wanted, alive, loop](ml::Frame frame) {
    // Read at connect, and posted too: the fence upload confirms its PARAM_SETs on the loop.
    if (auto pv = ml::unpack_param_value(frame.message); pv && frame.compid == ml::comp::AUTOPILOT1) {
      std::lock_guard lock(first->mutex);
      if (first->heard && frame.sysid == first->sysid) first->params[pv->param_id] = pv->param_value;
      first->cv.notify_all();
    }
    if (auto hb = ml::unpack_heartbeat(frame.message);
        hb && hb->autopilot != ml::autopilot::INVALID && (wanted == 0 || frame.sysid == wanted)) {
      std::lock_guard lock(first->mutex);
      if (!first->heard) {
        first->heard = true;
        first->sysid = frame.sysid;
        first->autopilot = hb->autopilot;
      }
      if (frame.sysid == first->sysid && frame.signature_verified) first->signed_heard = true;
      first->cv.notify_all();
    }
    loop->post([this, alive, frame = std::move(frame)] {
      if (alive.lock()) on_frame_(frame);
    });
  };
}

std::string VehicleLink::connect(const fleet::Endpoint& endpoint) {
  auto first = std::make_shared<FirstHeartbeat>();
  const uint8_t wanted = static_cast<uint8_t>(settings_.sysid);
  std::optional<ml::SigningKey> key;
  if (!settings_.signing_key.empty()) {
    std::string error;
    key = ml::parse_signing_key(settings_.signing_key, error);
    if (!key) return "signing key of " + settings_.name + ": " + error;
  }
  // With a key the vehicle must sign from the first frame on, unless we are to give it the
  // key (setup): then its unsigned frames count until it signs.
  ml::OpenResult opened = ml::Link::open(endpoint, receiver(first, wanted), 1.0, key, key && !settings_.signing_setup);
  if (!opened.link) return opened.error;
  link_ = std::move(opened.link);
  link_->follow_only(wanted);

  std::unique_lock lock(first->mutex);
  auto wait = std::chrono::duration<double>(options_.connect_timeout_s);
  if (!first->cv.wait_for(lock, wait, [&] { return first->heard; })) {
    lock.unlock();
    std::string error = no_heartbeat(endpoint, wanted, key.has_value());
    link_.reset();
    return error;
  }
  if (std::string error = identify(*first, lock, endpoint, key); !error.empty()) {
    if (lock.owns_lock()) lock.unlock();
    link_.reset();
    return error;
  }
  send_heartbeat();
  return "";
}

std::string VehicleLink::no_heartbeat(const fleet::Endpoint& endpoint, uint8_t wanted, bool signing) const {
  char text[64];
  std::snprintf(text, sizeof text, "%.0f s", options_.connect_timeout_s);
  std::string who = wanted ? "system " + std::to_string(wanted) : std::string("any autopilot");
  std::string on = signing ? " Signing is on for this drone: unsigned or badly signed frames are dropped (" +
                                 std::to_string(link_->stats().signing_dropped) +
                                 " so far); does the vehicle have this key (`setup: true` gives it)?"
                           : "";
  return "no HEARTBEAT from " + who + " on " + endpoint.url + " within " + text +
         "; is the vehicle (or its SITL) running and sending to this address, with this system id?" + on;
}

std::string VehicleLink::identify(FirstHeartbeat& first, std::unique_lock<std::mutex>& lock,
                                  const fleet::Endpoint& endpoint, const std::optional<ml::SigningKey>& key) {
  sysid_ = first.sysid;
  autopilot_ = autopilot_for(first.autopilot);
  if (!autopilot_)
    return "system " + std::to_string(sysid_) + " on " + endpoint.url + " reports MAV_AUTOPILOT " +
           std::to_string(first.autopilot) + "; the mavlink adapter flies PX4 (12) and ArduPilot (3)";
  link_->follow_only(sysid_);  // from now on only the vehicle's frames move a udp:// link
  encoder_ = {sysid_, ml::comp::ONBOARD_COMPUTER, 0};
  if (key) {
    if (std::string error = give_key(first, lock, *key); !error.empty()) return error;
    encoder_.signer.emplace(*key, kSigningLinkId);  // every frame from here on is signed
  }
  read_limits(first, lock);
  return "";
}

// Before the mission starts, so that its first deadline already knows how fast the
// autopilot flies.
void VehicleLink::read_limits(FirstHeartbeat& first, std::unique_lock<std::mutex>& lock) {
  std::map<std::string, float> values =
      read_params(first, lock, limit_params(*autopilot_), options_.param_timeout_s, [this](const char* name) {
        send(ml::pack(ml::ParamRequestRead{sysid_, ml::comp::AUTOPILOT1, name, -1}));
      });
  lock.unlock();
  limits_ = combine_limits(*autopilot_, mid::flight_limits(settings_), values);
  for (const std::string& w : limits_.warnings) diag::Logger{"mavlink", settings_.name}.warning(w);
}

// setup: true: SETUP_SIGNING to the vehicle (again every half second) until its first signed
// HEARTBEAT, then unsigned frames are dropped. Sent unsigned: a vehicle without a key drops
// signed frames it cannot check (ours does; ArduPilot would take them), and one with another
// key must refuse it anyway. Without setup the vehicle has signed from its first frame (the
// link required it), and there is nothing to do.
std::string VehicleLink::give_key(FirstHeartbeat& first, std::unique_lock<std::mutex>& lock,
                                  const ml::SigningKey& key) {
  if (!settings_.signing_setup) return "";
  ml::SetupSigning setup{sysid_, ml::comp::AUTOPILOT1, key.bytes, ml::signing_time_now()};
  auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(options_.connect_timeout_s);
  while (!first.signed_heard && std::chrono::steady_clock::now() < until) {
    send(ml::pack(setup));
    first.cv.wait_for(lock, std::chrono::milliseconds(500), [&] { return first.signed_heard; });
  }
  if (!first.signed_heard)
    return "system " + std::to_string(sysid_) + " did not sign its frames after SETUP_SIGNING within " +
           std::to_string(static_cast<int>(options_.connect_timeout_s)) +
           " s; does its autopilot support MAVLink 2 signing (ArduPilot does; PX4 needs MAV_SIGN_CFG)?";
  link_->require_signed(true);
  diag::Logger{"mavlink", settings_.name}.info("system " + std::to_string(sysid_) +
                                               " took the signing key; unsigned frames are dropped from now on");
  return "";
}

void VehicleLink::send(const ml::Message& m) {
  if (link_) link_->send(encoder_.encode(m));
}

ml::CommandLong VehicleLink::command(uint16_t id, std::array<float, 7> params) const {
  ml::CommandLong c;
  c.target_system = sysid_;
  c.target_component = ml::comp::AUTOPILOT1;
  c.command = id;
  c.param = params;
  return c;
}

void VehicleLink::send_heartbeat() {
  ml::Heartbeat hb;
  hb.type = ml::mav_type::ONBOARD_CONTROLLER;
  hb.autopilot = ml::autopilot::INVALID;
  hb.system_status = ml::state::ACTIVE;
  send(ml::pack(hb));
  if (settings_.announce_as_gcs) {
    // PX4 sends STATUSTEXT (why it refused) only to a link where it heard a ground station
    // within 2.5 s. Asked for in the fleet file: it also keeps PX4's GCS link-loss failsafe
    // from seeing the real ground station go (docs/fleet.md, docs/adapters.md).
    hb.type = ml::mav_type::GCS;
    send(ml::pack(hb));
  }
  heartbeat_timer_ = loop_.after(1.0, [this] { send_heartbeat(); });
}

void VehicleLink::note_rejected(const char* what) {
  ++rejected_frames_;
  // The first few, then every thousandth: a flood of bad frames must not flood the log.
  if (rejected_frames_ <= 10 || rejected_frames_ % 1000 == 0)
    diag::Logger{"mavlink", settings_.name}.warning("dropped a frame of system " + std::to_string(sysid_) + ": " + what +
                                                    " (" + std::to_string(rejected_frames_) + " dropped so far)");
}

void VehicleLink::note_foreign() {
  uint64_t n = link_ ? link_->foreign_datagrams() : 0;
  if (n == foreign_reported_) return;
  bool first = foreign_reported_ == 0;
  bool thousandth = n / 1000 > foreign_reported_ / 1000;
  foreign_reported_ = n;
  if (!first && !thousandth) return;
  std::string text = "ignored " + std::to_string(n) + " datagram(s) from other addresses than system " +
                     std::to_string(sysid_) + "'s (not the vehicle: someone else is sending to this port)";
  diag::Logger{"mavlink", settings_.name}.warning(text);
  if (first) note_(text);
}

}  // namespace eamos::mavlink_adapter
