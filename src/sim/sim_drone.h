#pragma once
// The built-in simulator's drone: a kinematic multirotor behind the uniform drone API.
// Each SimDrone is stepped by the event loop at a fixed rate only while it moves; a drone
// standing still (on the ground or hovering) schedules nothing, so a fleet of idle drones
// costs nothing and a run on virtual time is as fast as the moving drones' steps.
// Deterministic: the same calls at the same mission times give the same states.
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "fleet/catalog.h"
#include "fleet/fleet.h"
#include "mid/adapter_drone.h"
#include "mid/drone_api.h"
#include "mid/event_loop.h"
#include "mid/mover.h"
#include "mid/state_broker.h"
#include "sim/battery.h"
#include "sim/motion.h"

namespace eamos::sim {

struct SimOptions {
  double step_hz = 20.0;           ///< motion steps while moving (positive); also the telemetry
                                   ///< rate then
  double idle_telemetry_hz = 1.0;  ///< telemetry while armed and still, only when subscribed
                                   ///< (the battery drains); 0 = only on state changes
  double picture_s = 0.5;          ///< TakePicture duration
  double sensor_read_s = 0.1;      ///< SensorK read duration
};

class SimDrone final : public mid::AdapterDrone {
 public:
  SimDrone(fleet::DroneSettings settings, fleet::DroneType type, mid::EventLoop& loop,
           SimOptions options = {});
  ~SimDrone() override;

  const std::string& name() const override { return settings_.name; }
  std::optional<double> progress(mid::ActionId id) const override;
  mid::DroneState state() const override;
  mid::SubscriptionId subscribe(mid::StateCallback fn) override;
  void unsubscribe(mid::SubscriptionId id) override;
  void failsafe(fleet::Failsafe what) override;

  /// Motion steps taken so far: the simulator's cost (idle drones take none).
  std::uint64_t steps() const { return steps_; }
  /// Current velocity, m/s (for tests of the limits).
  fleet::Vec3 velocity() const { return kin_.velocity; }

 private:
  std::string refusal(const mid::ActionRequest& r, const fleet::ActionSpec& spec) const override;
  double timeout_for(const mid::ActionRequest& r) const override;
  void start_system(mid::ActionId id, const mid::ActionRequest& r) override;
  void start_payload(mid::ActionId id, const mid::ActionRequest& r) override;
  void start_motion(mid::ActionId id, const mid::ActionRequest& r) override;
  void started() override { update_timers(); }
  void finish_payload(mid::ActionId id, const std::string& name);

  void stop_action(mid::ActionId id) override;  ///< what cancel and timeouts do to the vehicle
  bool hold_vehicle(mid::ActionId id, double climb_m) override;
  void resume_vehicle(mid::ActionId id) override;
  double distance_left(mid::ActionId id) const override;
  std::optional<fleet::Vec3> goal_of(mid::ActionId id) const override;
  void stop_motion();                           ///< brake and hold where it is
  /// Ends every running action as `end` says and flies the failsafe `what`.
  void enter_failsafe(fleet::Failsafe what, const mid::ActionEnd& end);

  void step();
  void set_armed(bool armed);
  void set_landed(bool landed);
  void phase_changed();  ///< battery rate and depletion timer follow armed/landed
  void battery_empty();
  void publish();
  void hand_out(const mid::DroneState& s);  ///< to the site-limits watch and the subscribers
  /// Everything of a state but its sensors' names, which `s` already holds in order.
  void fill_state(mid::DroneState& s) const;
  void post_publish();   ///< publish from the loop (for changes made inside API calls)
  void update_timers();  ///< steps while moving, idle telemetry while armed and still
  double sensor_value(int k) const;
  void write_mode(std::string& mode) const;  ///< the state's mode: what the motors do
  double ground_z() const { return settings_.home.z; }
  /// The fleet file's `gust:` pushes the drone now (in the air, within its time window).
  bool gust_blows() const;
  void gust_changed();  ///< at the gust's start and end: steps follow it

  fleet::DroneSettings settings_;
  /// "Sensor1" … "SensorN" of the type and the fleet file's model of each (null: reads 0),
  /// looked up once: a state is built on every step of every drone.
  std::vector<std::pair<std::string, const fleet::SensorModel*>> sensor_models_;
  /// The same names, each with its reading when it never changes (its base, or 0 without a
  /// model): what a state starts from.
  mid::SensorValues sensor_names_;
  std::vector<const fleet::SensorModel*> sensor_names_models_;  ///< each of sensor_names_'s model
  bool sensors_vary_ = false;  ///< a reading depends on the position: fill_state works them out
  /// The state publish() hands its subscribers, refilled in place at every step: a state
  /// built anew costs an allocation and a copy of every sensor's name (20 a second per
  /// moving drone). A publish from inside a subscriber builds its own.
  mid::DroneState published_;
  bool publishing_ = false;
  SimOptions options_;

  mid::Kinematics kin_;
  bool armed_ = false;
  bool landed_ = true;
  int pictures_ = 0;
  double heading_ = 0.0;  ///< degrees from north; a drone starts facing north
  Battery battery_;

  Motion motion_;
  mid::ActionId motion_owner_ = mid::kNoAction;  ///< the action motion_ flies for; none in failsafe
  /// The owner's motion while it gives way (hold_vehicle): flown on by resume_vehicle.
  std::optional<Motion> held_motion_;
  mid::StateBroker broker_;

  mid::TimerId step_timer_ = mid::kNoTimer;
  double steps_origin_ = 0.0;     ///< mission time of step 0 of the current run of steps
  std::uint64_t steps_in_run_ = 0;
  std::uint64_t steps_ = 0;
  mid::TimerId telemetry_timer_ = mid::kNoTimer;
  mid::TimerId empty_timer_ = mid::kNoTimer;
  mid::TimerId publish_timer_ = mid::kNoTimer;
  mid::TimerId gust_timer_ = mid::kNoTimer;
};

}  // namespace eamos::sim
