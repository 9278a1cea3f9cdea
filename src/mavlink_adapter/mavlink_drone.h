#pragma once
// A vehicle flown over MAVLink behind the uniform drone API. The adapter is an onboard
// controller on the vehicle's system (component 191): it sends its own HEARTBEAT at 1 Hz,
// asks for the telemetry it needs with SET_MESSAGE_INTERVAL, and flies
//   Arm/Disarm      MAV_CMD_COMPONENT_ARM_DISARM
//   Takeoff         MAV_CMD_NAV_TAKEOFF (ArduPilot: after switching to GUIDED)
//   Land            MAV_CMD_NAV_LAND, done when EXTENDED_SYS_STATE says on ground
//   ReturnHome      MAV_CMD_NAV_RETURN_TO_LAUNCH, done when on ground
//   FlyTo, FlyBy*   position setpoints (SET_POSITION_TARGET_LOCAL_NED) in OFFBOARD/GUIDED
//   Hover           a position setpoint where the drone is
//   Orbit           PX4: MAV_CMD_DO_ORBIT around where it is, flown in PX4's Orbit mode;
//                   ArduPilot (Copter has no DO_ORBIT): setpoints moving around the circle
//   TakePicture     ArduPilot MAV_CMD_IMAGE_START_CAPTURE, PX4 MAV_CMD_DO_DIGICAM_CONTROL;
//                   done once the vehicle confirms the picture (CAMERA_TRIGGER, _FEEDBACK or
//                   CAMERA_IMAGE_CAPTURED), not at the ACK
//   SensorK         the fleet file's sensor model at the drone's position (MAVLink has no
//                   standard "mission sensor"; a real payload needs its own adapter code)
// Every frame arrives on the link's thread and is posted to the event loop, so all state
// here is touched by the loop's thread only. No HEARTBEAT for `link_timeout_s` = link lost:
// the running actions end `failed` and new ones are refused until heartbeats return.
#include <array>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "mavlink/link.h"
#include "mavlink_adapter/autopilot.h"
#include "mavlink_adapter/autopilot_params.h"
#include "mavlink_adapter/command_sender.h"
#include "mavlink_adapter/telemetry.h"
#include "mid/adapter_drone.h"
#include "mid/drone_api.h"
#include "mid/location_validator.h"
#include "mid/state_broker.h"

namespace eamos::mavlink_adapter {

struct FirstHeartbeat;  ///< mavlink_drone_link.cpp

struct MavlinkOptions {
  bool real_time = false;          ///< the loop runs in real time: required (a real vehicle
                                   ///< cannot follow virtual time)
  /// Mission seconds per wall second of the loop (--speed). The link's budgets below are
  /// wall-clock (network, scheduling), so register_adapter scales them by it; a vehicle sped
  /// up as much then gets the same slack in wall time as a real one.
  double speed = 1.0;
  double connect_timeout_s = 10.0; ///< wall seconds to wait for the vehicle's first HEARTBEAT
  /// Mission seconds without a HEARTBEAT = link lost. Mission time, not wall time: what
  /// matters is how far the vehicle flies unheard, and every action's deadline is mission
  /// time too, so a lost link is seen before the running motion's deadline at any --speed.
  double link_timeout_s = 3.0;
  /// ... but never less than this many wall seconds: the ground's own scheduling must not
  /// look like a lost link (0.5 s was too little: with --distributed and three PX4 SITL on a
  /// loaded 2-core machine all three links "dropped" at once). At --speed 5: 7.5 mission s,
  /// still before the deadline of a FlyBy of a few metres.
  double link_timeout_min_wall_s = 1.5;
  CommandOptions commands;         ///< ACK timeouts in wall seconds
  double setpoint_hz = 10.0;       ///< setpoint stream rate (PX4 needs > 2 Hz in OFFBOARD)
  int setpoints_before_switch = 5; ///< PX4: setpoints sent before asking for OFFBOARD
  double position_hz = 10.0;       ///< LOCAL_POSITION_NED rate asked for
  /// HEARTBEAT rate asked for: the armed flag travels only there, and a disarm (the
  /// autopilot's auto-disarm on the ground) must be seen within 100 ms, latency included.
  /// PX4 refuses it (poll_heartbeat).
  double heartbeat_hz = 20.0;
  /// Wall seconds at connect to read the autopilot's speed parameters (PARAM_REQUEST_READ,
  /// resent every half second); what has not come by then keeps the fleet's limit.
  double param_timeout_s = 3.0;
  /// After an accepted mode switch, how long a HEARTBEAT in another mode still counts as sent
  /// before the switch took effect (seconds; scaled like the link's budgets).
  double mode_confirm_s = 3.0;
  /// ArduPilot queues the STATUSTEXT that explains a refusal and sends it after the
  /// COMMAND_ACK: a refused action waits this long for it (seconds; scaled).
  double statustext_wait_s = 0.5;
  /// A picture counts once the vehicle confirms it (CAMERA_TRIGGER, CAMERA_FEEDBACK or
  /// CAMERA_IMAGE_CAPTURED), not when the command is accepted: an autopilot accepts the
  /// command with no camera behind it. How long after the ACK to wait (seconds; scaled).
  double picture_confirm_s = 2.0;
};

class MavlinkDrone final : public mid::AdapterDrone {
 public:
  MavlinkDrone(fleet::DroneSettings settings, fleet::DroneType type, mid::EventLoop& loop,
               MavlinkOptions options);
  ~MavlinkDrone() override;

  /// Opens the link and waits (blocking, up to connect_timeout_s) for the vehicle's first
  /// HEARTBEAT; "" on success, else what went wrong and what to check.
  std::string connect(const mavlink::Endpoint& endpoint);

  const std::string& name() const override { return settings_.name; }
  std::optional<double> progress(mid::ActionId id) const override;
  mid::DroneState state() const override;
  mid::SubscriptionId subscribe(mid::StateCallback fn) override;
  void unsubscribe(mid::SubscriptionId id) override { broker_.unsubscribe(id); }
  void failsafe(fleet::Failsafe what) override;
  void set_message_sink(std::function<void(const std::string&)> sink) override { message_sink_ = std::move(sink); }
  bool has_global_frame() const override { return true; }
  std::optional<mid::GlobalFix> global_fix() const override;  // home_fix.cpp

  /// The limits deadlines are derived from: the slower of the fleet's and the autopilot's
  /// (known after connect()), and what to warn about at start.
  const FlightLimits& flight_limits() const { return limits_; }

  /// The autopilot row chosen from the first HEARTBEAT; nullptr before connect().
  const Autopilot* autopilot() const { return autopilot_; }
  bool link_lost() const { return link_lost_; }

 private:
  enum class Until { reached, landed, forever };
  struct Orbit {
    bool active = false;
    fleet::Vec3 centre;
    double radius = 0.0;
    double angle = 0.0;     ///< rad from east, counter-clockwise
    bool on_circle = false;
    bool commanded = false; ///< the autopilot flies it (DO_ORBIT accepted), not our setpoints
    bool mode_seen = false; ///< a HEARTBEAT has shown the autopilot's orbit mode
    double commanded_radius = 0.0;  ///< our setpoints' (or DO_ORBIT's) radius: `radius`
                                    ///< corrected by the radius flown
    // DO_ORBIT's radius correction (mavlink_drone_orbit.cpp, correct_orbit_radius)
    double sent_radius = 0.0;       ///< the radius the autopilot flies to, as last sent
    double sent_speed = 0.0;        ///< ... and its speed
    double flown_speed = 0.0;       ///< along the circle, smoothed like last_flown_m
    double outward_mps = 0.0;       ///< how fast the radius flown grows, smoothed
    double previous_flown_m = 0.0;  ///< the radius flown at the previous report
    double sent_at_s = 0.0;         ///< vehicle s the last correction was sent
    double last_report_s = -1.0;    ///< vehicle s of the previous GLOBAL_POSITION_INT
    double last_flown_m = 0.0;      ///< the radius flown, smoothed over kFlownSmoothingS
    double recent_flown_m = 0.0;    ///< ... smoothed over kRecentSmoothingS only
    bool correcting = false;        ///< a correction waits for its COMMAND_ACK
    bool corrections_stopped = false;  ///< one was refused (or never answered): no more
    /// The centre in degE7, named to PX4 in DO_ORBIT (centre_known: a global position was at
    /// hand when the orbit started).
    bool centre_known = false;
    int32_t centre_lat_e7 = 0, centre_lon_e7 = 0;
    bool do_orbit_sent = false;
    bool centre_compared = false;  ///< the autopilot's centre has been traced beside ours
    double waited_at_start_s = 0.0;  ///< mission s at the east point, waiting to be still
  };

  // actions (mavlink_drone.cpp)
  std::optional<mid::ActionEnd> unavailable() const override;
  std::string refusal(const mid::ActionRequest& r, const fleet::ActionSpec& spec) const override;
  void start_system(mid::ActionId id, const mid::ActionRequest& r) override;
  void start_payload(mid::ActionId id, const mid::ActionRequest& r) override;
  void take_picture(mid::ActionId id);
  void on_camera_capture(const mavlink::CameraCapture& c);
  void end_picture(mid::ActionId id);  ///< acknowledged and confirmed: taken
  void start_motion(mid::ActionId id, const mid::ActionRequest& r) override;
  void start_takeoff(mid::ActionId id, double altitude);
  void send_takeoff(mid::ActionId id, double altitude, std::array<float, 7> p);
  /// A motion command the autopilot took: it flies it in its own mode now.
  void autopilot_flies_it();
  void repeat_takeoff(mid::ActionId id, double altitude, uint64_t heartbeats_before, double waited_s);
  /// Arms, first switching to a mode where arming is allowed when the vehicle is in one where
  /// it is not (ArduPilot cannot arm in LAND, where a landing leaves it); `armed` runs once
  /// the autopilot accepted.
  void arm(mid::ActionId id, std::function<void()> armed);
  void send_arm(mid::ActionId id, std::function<void()> armed);
  double timeout_for(const mid::ActionRequest& r) const override;
  void command_motion(mid::ActionId id, uint16_t cmd, std::array<float, 7> params = {});
  /// The autopilot refused (or never answered) a command of `id`: it ends `failed`, refused
  /// (timed_out without an answer), its MAV_RESULT and STATUSTEXT the detail.
  void end_refused(mid::ActionId id, const CommandResult& result);
  void stop_action(mid::ActionId id) override;
  std::string timeout_detail(mid::ActionId id) const override;
  double distance_left(mid::ActionId id) const override;
  double closing_window_s(const mid::ActionRequest& r) const override;
  /// vehicle_clock_rate() as mission_s() allows for it: within 0.2 … 1.
  double deadline_clock_rate() const override;
  void hold_here();
  /// Ends every running action `failed` for `why`, dropping the motion's goal and orbit.
  void fail_all(mid::FailureReason why, const std::string& reason);
  /// Ends the motion the adapter flies (if any) `failed`, dropping its goal and orbit.
  void fail_motion(mid::FailureReason why, const std::string& reason, const std::string& detail);

  /// fleet `signing: {setup: true}`: gives the vehicle the key at connect (mavlink_drone_link.cpp).
  std::string give_key(FirstHeartbeat& first, std::unique_lock<std::mutex>& lock, const mavlink::SigningKey& key);

  // the vehicle's own words (mavlink_drone_link.cpp)
  void on_statustext(const mavlink::Statustext& t);
  /// "; ArduPilot says: …": its warnings and errors since `since` (mission s), or "".
  std::string autopilot_says(double since) const;
  void note(const std::string& text);  ///< to the trace (message sink)
  void on_armed_changed();
  /// Folds a LOCAL_POSITION_NED's time_boot_ms into the vehicle's clock rate.
  void on_vehicle_clock(uint32_t time_boot_ms);
  /// Vehicle seconds per mission second over the last few seconds (1 until known).
  double vehicle_clock_rate() const;
  /// `vehicle_s` seconds of the vehicle's time in mission seconds, for a deadline or a wait:
  /// never shorter (a vehicle clock ahead of ours is jitter), at most 5 times longer.
  double mission_s(double vehicle_s) const;
  /// A disarm by the autopilot while our Takeoff waits on the ground: arm and take off again.
  bool takeoff_disarmed_on_ground();
  /// A motion still running on a vehicle down and disarmed (not by the mission): it fails.
  void end_motion_on_the_ground();
  void disarm_after_failsafe_landing();

  // link, telemetry, setpoints (mavlink_drone_link.cpp)
  void on_frame(const mavlink::Frame& frame);
  /// A frame of the vehicle refused for its values: counted and logged, never applied.
  void note_rejected(const char* what);
  /// Datagrams the udp:// link dropped for coming from another address than the vehicle's:
  /// logged (the first, then every thousandth) and the first one put in the trace.
  void note_foreign();
  void on_heartbeat();
  /// MAV_CMD_REQUEST_MESSAGE(HEARTBEAT) at heartbeat_hz while on the ground, for an
  /// autopilot that keeps its own HEARTBEAT rate.
  void poll_heartbeat();
  void link_watchdog();
  void lose_link();
  void request_telemetry();
  void check_goal();
  void send(const mavlink::Message& m);
  void send_heartbeat();
  mavlink::CommandLong command(uint16_t id, std::array<float, 7> params = {}) const;
  void stream_setpoints();
  void stream_tick();

  // orbit (mavlink_drone_orbit.cpp)
  double orbit_speed(double radius) const;
  void start_orbit(fleet::Vec3 centre, double radius);  ///< for motion_owner_
  std::string orbit_radius_refusal(double radius) const;  ///< "" when the autopilot takes it
  void send_do_orbit();  ///< PX4: DO_ORBIT around orbit_'s centre, from where the vehicle is
  void orbit_stopped_in_flight();
  void leave_orbit();
  bool left_orbit_mode();  ///< the vehicle left DO_ORBIT's mode: the orbit failed
  void advance_orbit(double dt);
  bool done_moving_out() const;
  /// PX4, out to its circle on our setpoints: the heading (rad from north) that faces the centre.
  std::optional<double> orbit_setpoint_yaw() const;
  double near_orbit_start_m() const;
  bool faces_orbit_centre() const;  ///< within kFacingDeg, or the heading is not known
  /// DO_ORBIT: PX4 flies its circle a little off the radius asked for (docs/adapters.md);
  /// from each position report (vehicle s) the radius asked for is corrected by the one flown.
  void correct_orbit_radius();  ///< on a GLOBAL_POSITION_INT while the autopilot orbits
  void trace_orbit_centre();
  double led_radius() const;     ///< the radius a correction sends, before its bounds
  void send_due_orbit_correction();  ///< on a HEARTBEAT: the correction, if one is due
  std::array<float, 7> do_orbit_params(double radius, double speed) const;
  void switch_to_setpoint_mode();
  void send_mode_command(mavlink::CommandLong c, CommandDone done, std::function<bool()> resend_while = nullptr);
  void send_mode_command(const mavlink::CommandInt& c, CommandDone done);
  CommandDone counted_mode_command(CommandDone done);  ///< mode_commands_pending_ while it is out
  void publish();
  fleet::Vec3 position() const;
  fleet::Vec3 reference() const;  ///< where relative motions start: holding_ or position()
  double ground_z() const { return settings_.home.z; }
  double sensor_value(int k) const;
  double remaining(fleet::Vec3 from) const;  ///< path still to fly for the running motion

  fleet::DroneSettings settings_;
  MavlinkOptions options_;
  const Autopilot* autopilot_ = nullptr;
  uint8_t sysid_ = 0;  ///< the vehicle's system id (0 until known)
  uint64_t rejected_frames_ = 0;  ///< frames of the vehicle refused for their values
  uint64_t foreign_reported_ = 0; ///< link's foreign_datagrams() when last looked at

  /// Posted frames hold a weak pointer to this: a frame that reaches the loop after the
  /// drone is gone is dropped instead of touching freed memory.
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
  std::unique_ptr<mavlink::Link> link_;
  mavlink::Encoder encoder_;
  CommandSender commands_;
  mid::StateBroker broker_;
  VehicleState vehicle_;
  bool link_lost_ = false;
  bool telemetry_requested_ = false;
  int pictures_ = 0;
  struct Picture {
    bool acked = false;      ///< the autopilot accepted the command
    bool confirmed = false;  ///< the camera said it took one
  };
  std::map<mid::ActionId, Picture> pictures_pending_;  ///< oldest first (ids grow)
  std::optional<int64_t> last_image_index_;  ///< the image that confirmed the last picture
  FlightLimits limits_;
  std::function<void(const std::string&)> message_sink_;
  struct Text {
    double t;
    uint8_t severity;
    std::string text;
  };
  std::deque<Text> texts_;  ///< the autopilot's recent STATUSTEXTs, newest last
  std::map<uint16_t, std::string> chunks_;  ///< STATUSTEXT id -> the chunks so far
  /// The mission armed the vehicle and it has not taken off since: an autopilot's auto-disarm
  /// in this state is survived by arming again before the Takeoff.
  bool armed_waiting_ = false;
  bool disarm_commanded_ = false;  ///< a disarm now is ours (Disarm, failsafe), not the autopilot's
  mid::ActionId takeoff_rearmed_ = mid::kNoAction;  ///< the Takeoff already re-armed once
  uint32_t takeoff_attempt_ = 0;  ///< NAV_TAKEOFFs sent; an answer to an older one is stale
  uint64_t heartbeats_ = 0;       ///< HEARTBEATs of the autopilot so far
  bool heartbeat_requested_ = false;  ///< a REQUEST_MESSAGE(HEARTBEAT) waits for its ACK
  mid::ActionId takeoff_repeating_ = mid::kNoAction;  ///< the Takeoff waiting to repeat a refused NAV_TAKEOFF
  /// (mission s, vehicle s) of recent position reports: a SITL on a loaded machine runs
  /// slower than --speed, and every deadline is stretched by how much (timeout_for()).
  std::deque<std::pair<double, double>> clock_samples_;
  bool clock_noted_ = false;

  // the motion the adapter flies for an action
  mid::ActionId motion_owner_ = mid::kNoAction;
  Until until_ = Until::forever;
  fleet::Vec3 motion_start_;      ///< where the running motion started, for progress()
  std::optional<mid::LocationValidator> goal_;
  /// The goal the vehicle holds after reaching it; the next FlyBy counts from it, not from
  /// the measured position, so the estimator's centimetres do not add up over a mission.
  std::optional<fleet::Vec3> holding_;
  bool streaming_ = false;        ///< setpoints are the vehicle's control (else: its own modes)
  bool in_control_ = false;       ///< the vehicle entered the setpoint mode for our stream; if
                                  ///< it leaves it (a pilot, a failsafe), we do not fight it
  /// A HEARTBEAT has shown the setpoint mode since we last asked for it. Until then a
  /// HEARTBEAT in another mode is one sent before the switch took effect (PX4 acknowledges
  /// DO_SET_MODE a cycle before its mode changes), not somebody taking over.
  bool mode_confirmed_ = false;
  double mode_granted_at_ = 0.0;  ///< loop time the setpoint mode was last granted
  fleet::Vec3 setpoint_;          ///< mission frame
  Orbit orbit_;  ///< active: our setpoints fly it; commanded: the autopilot does
  int setpoints_sent_ = 0;
  /// Commands in flight that change the flight mode (DO_SET_MODE, NAV_TAKEOFF, NAV_LAND,
  /// NAV_RETURN_TO_LAUNCH): meanwhile a HEARTBEAT in another mode is expected, not a takeover,
  /// and the stream does not ask for the setpoint mode again.
  int mode_commands_pending_ = 0;

  mid::TimerId stream_timer_ = mid::kNoTimer;
  mid::TimerId heartbeat_timer_ = mid::kNoTimer;
  mid::TimerId watchdog_timer_ = mid::kNoTimer;
  mid::TimerId heartbeat_poll_timer_ = mid::kNoTimer;  ///< poll_heartbeat's; none: the rate was granted
};

}  // namespace eamos::mavlink_adapter
