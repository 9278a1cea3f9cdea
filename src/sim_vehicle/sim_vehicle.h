#pragma once
// A PX4-like MAVLink vehicle on top of the built-in simulator, so the mavlink adapter is
// tested end to end without PX4: `eamos sim-vehicle` and the adapter tests run it. It
// behaves like PX4 where the adapter depends on it, and is simpler everywhere else (with the
// ArduPilot dialect, like ArduPilot Copter's GUIDED rules instead):
//  - HEARTBEAT at 1 Hz (MAV_AUTOPILOT_PX4, PX4 custom modes, armed flag);
//  - COMMAND_LONG answered with COMMAND_ACK: ARM_DISARM, NAV_TAKEOFF (param7 above mean
//    sea level; refused while disarmed), NAV_LAND, NAV_RETURN_TO_LAUNCH, DO_SET_MODE
//    (OFFBOARD only while setpoints stream, AUTO.LOITER/LAND/RTL), SET_MESSAGE_INTERVAL,
//    the dialect's picture command (acknowledged once the 0.5 s picture is taken, then
//    confirmed with the dialect's camera message), DO_ORBIT (PX4 only:
//    around where it is, in PX4's Orbit mode; sent again in that mode it keeps the centre
//    and changes radius and speed; ArduPilot Copter has none; as COMMAND_INT around the
//    centre it names, ORBIT_EXECUTION_STATUS reporting it while it orbits); anything else
//    MAV_RESULT_UNSUPPORTED. A resend (confirmation > 0) of the last command is
//    acknowledged again, not executed twice;
//  - SET_POSITION_TARGET_LOCAL_NED flown in OFFBOARD; setpoints older than 1 s there fall
//    back to AUTO.LOITER (PX4's offboard loss failsafe, COM_OF_LOSS_T); no arming in
//    OFFBOARD without them (PX4: MAV_RESULT_TEMPORARILY_REJECTED, "Arming denied: Resolve
//    system health failures first");
//  - telemetry (LOCAL_POSITION_NED, EXTENDED_SYS_STATE, SYS_STATUS, BATTERY_STATUS,
//    GLOBAL_POSITION_INT) at 1 Hz each, or the rate SET_MESSAGE_INTERVAL asks for;
//  - disarms 2 s after touching down (PX4's COM_DISARM_LAND);
//  - PARAM_REQUEST_READ of the autopilot's speed parameters answered with PARAM_VALUE, valued
//    as the simulator flies; PARAM_SET kept and answered with PARAM_VALUE (integers bytewise
//    in the PX4 dialect, as floats in ArduPilot's);
//  - the mission protocol for its fence (mission_type FENCE, sim_vehicle_fence.cpp): an
//    upload (MISSION_COUNT, its requests, MISSION_ITEM_INT, MISSION_ACK) and a read back
//    (MISSION_REQUEST_LIST); it keeps the polygon but does not fly by it.
// Its local NED origin is its home; it runs on its own event loop in real time.
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "mavlink/link.h"
#include "mavlink/payloads.h"
#include "mid/event_loop.h"
#include "sim/sim_drone.h"

namespace eamos::sim_vehicle {

/// What the vehicle is doing, whatever the autopilot calls it.
enum class Mode : uint8_t { manual, hold, setpoint, takeoff, land, rtl, orbit };
inline constexpr int kModes = 7;

/// How one autopilot names and rules its modes: the vehicle plays PX4 or ArduPilot Copter.
/// This is the vehicle's own description, written from the autopilots' documentation and
/// deliberately not shared with the adapter's table, so the tests compare two readings.
struct Dialect {
  const char* name;
  uint8_t mav_autopilot;
  uint32_t custom_mode[kModes];  ///< HEARTBEAT custom_mode per Mode
  Mode boot;                     ///< mode at start
  bool main_sub_modes;           ///< PX4: DO_SET_MODE param2 main, param3 sub; else param2 = mode
  bool takeoff_altitude_amsl;    ///< NAV_TAKEOFF param7 above sea level (PX4) or home (ArduPilot)
  bool takeoff_in_setpoint_mode; ///< ArduPilot Copter: NAV_TAKEOFF only in GUIDED
  bool setpoints_before_switch;  ///< PX4: no OFFBOARD without a setpoint stream
  bool setpoint_loss_holds;      ///< PX4: OFFBOARD falls back to hold when setpoints stop
  Mode after_takeoff;            ///< PX4: AUTO.LOITER; ArduPilot: stays in GUIDED
  bool do_orbit;                 ///< PX4 flies MAV_CMD_DO_ORBIT; ArduPilot Copter does not know it
  /// One picture: PX4's camera_trigger takes MAV_CMD_DO_DIGICAM_CONTROL and reports
  /// CAMERA_TRIGGER; ArduPilot's AP_Camera takes MAV_CMD_IMAGE_START_CAPTURE and reports
  /// CAMERA_FEEDBACK (each, in this vehicle, after the ACK).
  uint16_t picture_command;
  uint32_t picture_confirmation;
  /// PX4 keeps its HEARTBEAT at 1 Hz (SET_MESSAGE_INTERVAL answered MAV_RESULT_FAILED, SITL
  /// 1.18); ArduPilot streams it at the rate asked for.
  bool heartbeat_rate_fixed;
};
const Dialect& px4_dialect();
const Dialect& ardupilot_dialect();

struct VehicleOptions {
  const Dialect* dialect = &px4_dialect();
  uint8_t sysid = 1;
  double battery_percent = 100.0;  ///< charge at start (0: arming is refused)
  double home_amsl_m = 488.0;      ///< ground altitude above mean sea level (PX4 SITL's Zurich)
  /// Where it stands (its home, its local origin): this far east and north (m) of PX4 SITL's
  /// default home, 47.397742° N, 8.545594° E, as a fleet's vehicles stand apart on a field.
  double east_m = 0.0;
  double north_m = 0.0;
  /// Where its home is above the local frame's origin (negative: below), as GLOBAL_POSITION_INT's
  /// relative_alt tells. PX4 sets home where the vehicle stood when it armed, and its EKF's
  /// altitude drifts on the ground meanwhile: on SITL 0.2 m lower than the ground 15 s later.
  double home_above_origin_m = 0.0;
  double offboard_loss_s = 1.0;    ///< OFFBOARD without a fresh setpoint this long: hold
  /// The mode it starts in instead of its dialect's boot mode: where a previous mission left
  /// it. PX4 SITL stood disarmed in OFFBOARD (vehicle_status nav_state 14) after a mission
  /// that flew setpoints and ended with NAV_LAND and a disarm.
  std::optional<Mode> boot_mode;
  double disarm_after_land_s = 2.0;
  double default_rate_hz = 1.0;    ///< telemetry rate until SET_MESSAGE_INTERVAL says otherwise
  /// false: the picture command is accepted but no camera confirms it, as an autopilot whose
  /// camera is configured but absent (or broken) answers.
  bool camera_confirms = true;
  /// PX4's orbit (a velocity controller) flies its circle short of the radius it is given:
  /// SIH measured 4.12-5.10 m for 5 m (docs/adapters.md). This fraction short (negative:
  /// wide; 0: exact), to test that the adapter corrects it.
  double orbit_shortfall = 0.0;
  /// DO_ORBIT denied whatever it asks (as PX4 denies one it cannot fly), to test the refusal.
  bool refuse_orbit = false;
  /// The auto-disarm strikes as the first NAV_TAKEOFF arrives: the vehicle disarms and
  /// answers MAV_RESULT_FAILED, as ArduCopter SITL did when its DISARM_DELAY (10 s) ran out
  /// 40 ms before Listing 2's Takeoff, with eamos' HEARTBEAT still saying armed.
  bool disarm_at_first_takeoff = false;
  /// The auto-disarm of a vehicle armed on the ground that never took off (PX4's
  /// COM_DISARM_PRFLT, ArduPilot's DISARM_DELAY) after this many seconds; 0: never. It
  /// strikes right after a HEARTBEAT, the worst case for a ground station that waits for the
  /// next one, and says so as PX4 does to a ground station: STATUSTEXT "Disarmed by auto
  /// preflight disarming" (here to any link).
  double preflight_disarm_s = 0.0;
  /// Its own hover after a takeoff wanders this far east (m) at once, as PX4 SITL's did (up to
  /// 1 m within 5 s, its estimate moving); 0: it stays over where it took off.
  double hover_wander_east_m = 0.0;
  /// Its setpoint hold stands this far east of the setpoint (m), as PX4 SITL's OFFBOARD stood
  /// 0.6-0.7 m off the circle's east point for seconds; 0: it holds on the setpoint.
  double setpoint_standoff_east_m = 0.0;
  /// The velocity its LOCAL_POSITION_NED reports, as a fraction of the one it flies: PX4
  /// SITL's estimator read under 0.3 m/s while the vehicle still moved at 0.3-0.7 m/s; 1: true.
  double reported_velocity_scale = 1.0;
  /// How fast it flies, and the speed parameters it answers with (the simulator's by default).
  fleet::Limits limits;
  /// Its fence storage: an upload of more corners is refused with MAV_MISSION_NO_SPACE, as
  /// ArduPilot's is (FENCE_TOTAL, its EEPROM); 0: it keeps no fence and answers nothing.
  int fence_capacity = 100;
  /// Ignores the first this many MISSION_COUNTs of a fence upload, as a link losing them would.
  int fence_counts_ignored = 0;
  /// Ignores the first this many ARMs (no ACK, no arming), as a link losing them would; a
  /// resend after the adapter's ACK timeout then arms it.
  int arms_lost = 0;
  /// Right after the ACK of an ARM or DISARM, this many HEARTBEATs that still show the
  /// state from before, as an autopilot whose HEARTBEAT was made before the command took
  /// effect would send (MAVLink promises no order between the two).
  int stale_heartbeats_after_arming = 0;
  /// Its read back reports each corner this far north of where it was given (degE7): a
  /// vehicle that stored something else than it acknowledged.
  int32_t fence_read_back_shift_e7 = 0;
  /// Parameters a PARAM_SET does not change (the answer keeps the old value).
  std::set<std::string> read_only_params;
};

class SimVehicle {
 public:
  SimVehicle(mid::EventLoop& loop, VehicleOptions options);
  ~SimVehicle();
  SimVehicle(const SimVehicle&) = delete;
  SimVehicle& operator=(const SimVehicle&) = delete;

  /// Opens the link and starts heartbeats and telemetry; "" on success, else why not.
  std::string open(const fleet::Endpoint& endpoint);
  /// A second link, to a ground station (QGroundControl on udpout://127.0.0.1:14550): it gets
  /// every frame the vehicle sends, and what it sends is handled as from the first link, as
  /// an autopilot with a telemetry radio beside its companion computer does.
  std::string open_ground_station(const fleet::Endpoint& endpoint);

  Mode mode() const { return mode_; }
  /// The local port it receives on (anyone may send there, as a second GCS could).
  uint16_t local_port() const { return link_ ? link_->local_port() : 0; }
  const sim::SimDrone& drone() const { return drone_; }
  /// How many COMMAND_LONGs of this id it answered, accepted or refused (resends of the last
  /// one not counted): what a test asks the vehicle it flies against.
  int received(uint16_t command) const {
    auto it = received_.find(command);
    return it == received_.end() ? 0 : it->second;
  }
  /// How many SET_MESSAGE_INTERVALs asked for this message id, taken or refused.
  int intervals_asked(uint32_t message) const {
    auto it = intervals_asked_.find(message);
    return it == intervals_asked_.end() ? 0 : it->second;
  }
  /// The newest position setpoint (x east, y north, z up), if any came.
  std::optional<fleet::Vec3> setpoint() const {
    return have_setpoint_ ? std::optional<fleet::Vec3>(setpoint_) : std::nullopt;
  }
  /// The heading the newest position setpoint named (degrees from north), if it named one.
  std::optional<double> setpoint_yaw_deg() const { return setpoint_yaw_deg_; }
  /// The DO_ORBITs it accepted (the last 1000), oldest first: what a test reads the
  /// corrections from.
  const std::vector<mavlink::CommandLong>& orbit_commands() const { return orbit_commands_; }
  /// Where the orbit it entered last is centred, and where the vehicle was when it entered it.
  struct OrbitStart {
    fleet::Vec3 centre, vehicle;
  };
  OrbitStart orbit_start() const { return orbit_start_; }
  /// Whether a HEARTBEAT of this MAV_TYPE came from a non-autopilot (a GCS, a companion).
  bool heard_heartbeat_of_type(uint8_t type) const { return heartbeat_types_.contains(type); }
  /// The fence corners it accepted last (MISSION_ACK accepted), in upload order.
  const std::vector<mavlink::MissionItemInt>& fence() const { return fence_; }
  /// A parameter set with PARAM_SET, read as the dialect encodes it; nullopt if never set.
  std::optional<double> param(const std::string& name) const;
  /// How many fence items it asked for (with MISSION_REQUEST in the ArduPilot dialect).
  int fence_requests() const { return fence_requests_; }
  /// Where a point of the earth (degE7) lies in its frame (x east, y north of home), by its own
  /// earth model: how a test reads the fence it holds.
  std::pair<double, double> local_of(int32_t lat_e7, int32_t lon_e7) const;

 private:
  void on_frame(const mavlink::Frame& frame);
  void on_command(const mavlink::CommandLong& c);
  void on_command_int(const mavlink::CommandInt& c);
  void on_param_request(const mavlink::ParamRequestRead& r);
  void on_setup_signing(const mavlink::SetupSigning& s);
  // PARAM_SET and the fence's mission protocol (sim_vehicle_fence.cpp); false: not one of them
  bool on_fence_frame(const mavlink::Frame& frame);
  void on_param_set(const mavlink::ParamSet& p);
  void on_fence_count(const mavlink::Frame& frame, const mavlink::MissionCount& c);
  void on_fence_item(const mavlink::Frame& frame, const mavlink::MissionItemInt& item);
  void request_fence_item(const mavlink::Frame& frame, uint16_t seq);
  uint8_t execute(const mavlink::CommandLong& c);  ///< the MAV_RESULT to acknowledge with,
                                                  ///< or kAckLater
  uint8_t set_mode(Mode mode);
  /// The Mode a DO_SET_MODE asks for; false when the dialect has no such mode.
  bool requested_mode(const mavlink::CommandLong& c, Mode& out) const;
  /// Runs `action`, then acknowledges `command` with its outcome; `after` runs after an ACCEPTED.
  void start_then_ack(uint16_t command, const std::string& action, std::function<void()> after = nullptr);
  /// VehicleOptions::stale_heartbeats_after_arming, after an accepted ARM or DISARM.
  void send_stale_heartbeats();
  void on_setpoint(const mavlink::SetPositionTargetLocalNed& sp);
  void fly_to_setpoint();
  void start(const std::string& action, std::vector<double> args,
             std::optional<Mode> mode_after = std::nullopt);
  void ack(uint16_t command, uint8_t result);
  void after_touchdown();
  void check_offboard();
  bool setpoints_fresh() const;  ///< a setpoint came within offboard_loss_s
  // DO_ORBIT (sim_vehicle_orbit.cpp)
  /// `centre` (x, y of its frame) when the command names one (COMMAND_INT), else where it is.
  uint8_t start_orbit(const mavlink::CommandLong& c, std::optional<fleet::Vec3> centre);
  void orbit_tick();
  double flown_radius() const;  ///< the circle flown for the radius asked (orbit_shortfall)

  void set_rate(uint32_t message_id, double hz);
  void send_stream(uint32_t message_id);
  void check_preflight_disarm();
  mavlink::Message telemetry(uint32_t message_id) const;
  // telemetry's messages that are more than a field or two
  mavlink::Message local_position(const mid::DroneState& s, fleet::Vec3 velocity) const;
  mavlink::Message global_position(const mid::DroneState& s, fleet::Vec3 velocity) const;
  mavlink::Message orbit_status(const mid::DroneState& s) const;
  mavlink::Message heartbeat(const mid::DroneState& s) const;
  void send(const mavlink::Message& m);
  mavlink::OpenResult open_link(const fleet::Endpoint& endpoint);

  mid::EventLoop& loop_;
  VehicleOptions options_;
  sim::SimDrone drone_;
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);  ///< see VehicleLink::alive_
  std::unique_ptr<mavlink::Link> link_;
  std::unique_ptr<mavlink::Link> ground_station_;  ///< open_ground_station's link, or null
  mavlink::Encoder encoder_;

  const Dialect& dialect_;
  Mode mode_;
  fleet::Vec3 setpoint_;                ///< mission frame of the simulator (x east, y north, z up)
  bool have_setpoint_ = false;
  double setpoint_at_ = -1e9;           ///< loop time of the newest setpoint
  std::optional<double> setpoint_yaw_deg_;  ///< its yaw, when taken (type_mask bit 10 clear)
  fleet::Vec3 flying_to_;               ///< target of the running FlyTo
  bool flying_ = false;
  bool takeoff_seen_ = false;  ///< a NAV_TAKEOFF came (disarm_at_first_takeoff)
  std::optional<double> armed_at_;  ///< seen armed since (at a HEARTBEAT); none while disarmed
  bool flown_since_armed_ = false;  ///< preflight_disarm_s is for a vehicle that never took off
  uint16_t last_command_ = 0;           ///< for resends: acknowledge again, do not redo
  uint8_t last_result_ = 0;
  bool has_last_ = false;
  int pictures_taken_ = 0;
  uint8_t ack_to_system_ = 0;           ///< who sent the newest command: its ACK goes there
  uint8_t ack_to_component_ = 0;
  std::map<uint32_t, mid::TimerId> streams_;  ///< message id -> its next send
  std::map<uint32_t, double> rates_hz_;
  mid::TimerId offboard_timer_ = mid::kNoTimer;
  mid::TimerId disarm_timer_ = mid::kNoTimer;
  std::map<uint16_t, int> received_;
  int arms_seen_ = 0;  ///< ARMs received (arms_lost)
  std::map<uint32_t, int> intervals_asked_;
  std::set<uint8_t> heartbeat_types_;  ///< see heard_heartbeat_of_type
  std::vector<mavlink::CommandLong> orbit_commands_;
  std::vector<mavlink::MissionItemInt> fence_;     ///< the accepted fence
  std::vector<mavlink::MissionItemInt> incoming_;  ///< the fence being uploaded
  uint16_t incoming_next_ = 0;
  int fence_counts_seen_ = 0;
  int fence_requests_ = 0;
  std::map<std::string, mavlink::ParamSet> params_set_;

  /// The orbit flown in Mode::orbit: like PX4's orbit task, a point moved around the circle
  /// that the vehicle follows.
  struct Orbit {
    fleet::Vec3 centre;
    double radius = 0.0;
    double speed = 0.0;      ///< m/s along the circle
    double direction = 1.0;  ///< +1 counter-clockwise seen from above, -1 clockwise
    double angle = 0.0;      ///< rad from east, counter-clockwise
    bool on_circle = false;
  };
  Orbit orbit_;
  OrbitStart orbit_start_;
  mid::TimerId orbit_timer_ = mid::kNoTimer;
};

}  // namespace eamos::sim_vehicle
