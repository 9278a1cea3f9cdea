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
//
// MavlinkDrone decides what each action does and when it ends; the parts it composes do the
// rest, each with its own state: VehicleLink (the wire, connect, our HEARTBEAT), LinkWatch
// (heartbeats in, link loss, telemetry rates), VehicleClock (the vehicle's time against
// mission time), AutopilotTexts (STATUSTEXT), ModeCommands (mode changes in flight),
// SetpointStream (setpoints and the setpoint mode), OrbitFlight (Orbit) and Camera
// (TakePicture). The parts reach the actions only through the hooks it gives them.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "mavlink/link.h"
#include "mavlink_adapter/autopilot.h"
#include "mavlink_adapter/autopilot_params.h"
#include "mavlink_adapter/autopilot_texts.h"
#include "mavlink_adapter/camera.h"
#include "mavlink_adapter/command_sender.h"
#include "mavlink_adapter/fence_upload.h"
#include "mavlink_adapter/link_watch.h"
#include "mavlink_adapter/mavlink_options.h"
#include "mavlink_adapter/mode_commands.h"
#include "mavlink_adapter/orbit_flight.h"
#include "mavlink_adapter/setpoint_stream.h"
#include "mavlink_adapter/telemetry.h"
#include "mavlink_adapter/vehicle_clock.h"
#include "mavlink_adapter/vehicle_link.h"
#include "mid/adapter_drone.h"
#include "mid/drone_api.h"
#include "mid/location_validator.h"
#include "mid/state_broker.h"

namespace eamos::mavlink_adapter {

class MavlinkDrone final : public mid::AdapterDrone {
 public:
  MavlinkDrone(fleet::DroneSettings settings, fleet::DroneType type, mid::EventLoop& loop,
               MavlinkOptions options);
  ~MavlinkDrone() override;

  /// Opens the link and waits (blocking, up to connect_timeout_s) for the vehicle's first
  /// HEARTBEAT; "" on success, else what went wrong and what to check.
  std::string connect(const fleet::Endpoint& endpoint);

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
  const FlightLimits& flight_limits() const { return link_.limits(); }

  /// The autopilot row chosen from the first HEARTBEAT; nullptr before connect().
  const Autopilot* autopilot() const { return link_.autopilot(); }
  bool link_lost() const { return watch_.lost(); }
  /// The fence upload (fleet `geofence: {upload: true}`), once started; nullptr otherwise.
  const FenceUpload* fence_upload() const { return fence_.get(); }

 private:
  enum class Until { reached, landed, forever };

  // the parts' hooks into the actions (mavlink_drone.cpp)
  LinkWatch::Hooks watch_hooks();
  SetpointStream::Hooks stream_hooks();
  OrbitFlight::Hooks orbit_hooks();
  Camera::Hooks camera_hooks();

  // frames (mavlink_drone.cpp)
  void on_frame(const mavlink::Frame& frame);
  void on_heartbeat();
  void on_link_lost(const std::string& why);
  /// Starts the fence upload once the vehicle's global and local positions place its origin.
  void maybe_upload_fence();
  /// Arm after the fence is on the autopilot; false when Arm already ended or waits for it.
  bool arm_needs_fence(mid::ActionId id, const std::function<void()>& armed);
  void note(const std::string& text);  ///< to the trace (message sink)
  /// "; ArduPilot says: …": its warnings and errors since `since` (mission s), or "".
  std::string autopilot_says(double since) const;

  // actions (mavlink_drone_actions.cpp)
  std::optional<mid::ActionEnd> unavailable() const override;
  std::string refusal(const mid::ActionRequest& r, const fleet::ActionSpec& spec) const override;
  void start_system(mid::ActionId id, const mid::ActionRequest& r) override;
  void start_payload(mid::ActionId id, const mid::ActionRequest& r) override;
  void start_motion(mid::ActionId id, const mid::ActionRequest& r) override;
  double timeout_for(const mid::ActionRequest& r) const override;
  void command_motion(mid::ActionId id, uint16_t cmd, std::array<float, 7> params = {});
  /// A motion command the autopilot took: it flies it in its own mode now.
  void autopilot_flies_it();
  /// The autopilot refused (or never answered) a command of `id`: it ends `failed`, refused
  /// (timed_out without an answer), its MAV_RESULT and STATUSTEXT the detail.
  void end_refused(mid::ActionId id, const CommandResult& result);
  void stop_action(mid::ActionId id) override;
  std::string timeout_detail(mid::ActionId id) const override;
  double distance_left(mid::ActionId id) const override;
  std::optional<fleet::Vec3> goal_of(mid::ActionId id) const override;
  double closing_window_s(const mid::ActionRequest& r) const override;
  /// The vehicle clock's rate as deadlines allow for it: within 0.2 … 1.
  double deadline_clock_rate() const override { return clock_.deadline_rate(); }
  void hold_here();
  void check_goal();
  // giving way (mavlink_drone_give_way.cpp)
  bool hold_vehicle(mid::ActionId id, double climb_m) override;
  void resume_vehicle(mid::ActionId id) override;
  /// Ends every running action `failed` for `why`, dropping the motion's goal and orbit.
  void fail_all(mid::FailureReason why, const std::string& reason);
  /// Ends the motion the adapter flies (if any) `failed`, dropping its goal and orbit.
  void fail_motion(mid::FailureReason why, const std::string& reason, const std::string& detail);

  // arming, takeoff and the autopilot's auto-disarm (mavlink_drone_takeoff.cpp)
  /// Arms, first switching to a mode where arming is allowed when the vehicle is in one where
  /// it is not (ArduPilot cannot arm in LAND, where a landing leaves it); `armed` runs once
  /// the autopilot accepted.
  void arm(mid::ActionId id, std::function<void()> armed);
  void send_arm(mid::ActionId id, std::function<void()> armed);
  void start_takeoff(mid::ActionId id, double altitude);
  /// NAV_TAKEOFF's parameters for `altitude` above the ground, from `here`.
  std::array<float, 7> takeoff_params(double altitude, fleet::Vec3 here) const;
  void send_takeoff(mid::ActionId id, double altitude, std::array<float, 7> p);
  void repeat_takeoff(mid::ActionId id, double altitude, uint64_t heartbeats_before, double waited_s);
  void on_armed_changed();
  /// A disarm by the autopilot while our Takeoff waits on the ground: arm and take off again.
  bool takeoff_disarmed_on_ground();
  /// A motion still running on a vehicle down and disarmed (not by the mission): it fails.
  void end_motion_on_the_ground();
  void disarm_after_failsafe_landing();

  void publish();
  fleet::Vec3 position() const { return mission_position(vehicle_, settings_.home); }
  fleet::Vec3 reference() const;  ///< where relative motions start: holding_ or position()
  double ground_z() const { return settings_.home.z; }
  double sensor_value(int k) const;
  double remaining(fleet::Vec3 from) const;  ///< path still to fly for the running motion

  fleet::DroneSettings settings_;
  MavlinkOptions options_;
  std::function<void(const std::string&)> message_sink_;
  VehicleLink link_;
  CommandSender commands_;
  ModeCommands modes_;
  VehicleClock clock_;
  AutopilotTexts texts_;
  VehicleState vehicle_;
  mid::StateBroker broker_;
  LinkWatch watch_;
  SetpointStream stream_;
  OrbitFlight orbit_;
  Camera camera_;
  std::unique_ptr<FenceUpload> fence_;        ///< created at connect when the fence is to be uploaded
  bool fence_wanted_ = false;                 ///< `upload: true` and a polygon to upload
  std::vector<std::function<void()>> after_fence_;  ///< Arms waiting for the upload to end

  /// The mission armed the vehicle and it has not taken off since: an autopilot's auto-disarm
  /// in this state is survived by arming again before the Takeoff.
  bool armed_waiting_ = false;
  bool disarm_commanded_ = false;  ///< a disarm now is ours (Disarm, failsafe), not the autopilot's
  mid::ActionId takeoff_rearmed_ = mid::kNoAction;  ///< the Takeoff already re-armed once
  uint32_t takeoff_attempt_ = 0;  ///< NAV_TAKEOFFs sent; an answer to an older one is stale
  mid::ActionId takeoff_repeating_ = mid::kNoAction;  ///< the Takeoff waiting to repeat a refused NAV_TAKEOFF

  // the motion the adapter flies for an action
  mid::ActionId motion_owner_ = mid::kNoAction;
  Until until_ = Until::forever;
  fleet::Vec3 motion_start_;      ///< where the running motion started, for progress()
  std::optional<mid::LocationValidator> goal_;
  /// The goal the vehicle holds after reaching it; the next FlyBy counts from it, not from
  /// the measured position, so the estimator's centimetres do not add up over a mission.
  std::optional<fleet::Vec3> holding_;
};

}  // namespace eamos::mavlink_adapter
