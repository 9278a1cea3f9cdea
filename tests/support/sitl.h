#pragma once
// Real autopilot firmware for the tests: N ArduCopter or PX4 (SIH) SITL instances, started
// from the binary named by EAMOS_ARDUPILOT_SITL / EAMOS_PX4_SITL, each in its own temporary
// folder with its geographic home placed where the fleet file puts the drone. The fleet owns
// exactly the processes it started: its destructor stops them by pid, also when a test
// fails half-way, and nothing else on the machine is touched.
#include <sys/types.h>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "mavlink/payloads.h"

namespace eamos_test {

enum class Autopilot { ardupilot, px4 };

/// A drone's home in the mission frame (docs/adapters.md, "Connecting": x east, y north, metres).
struct SitlHome {
  double x = 0;
  double y = 0;
};

struct SitlOptions {
  Autopilot autopilot = Autopilot::ardupilot;
  std::vector<SitlHome> homes;  ///< one instance per home; instance i has system id i + 1
  /// Simulation speed of the flight: PX4_SIM_SPEED_FACTOR; ArduPilot boots faster
  /// (--speedup, sitl.cpp kArduPilotBootSpeedup) and wait_ready() sets SIM_SPEEDUP to this.
  double speedup = 1;
  /// The autopilot's instance number of instance 0: it picks the ports (ArduPilot TCP
  /// 5760 + 10 n, PX4 UDP 14540 + n), so two fleets on one machine do not meet. Unset, it is
  /// EAMOS_SITL_FIRST_INSTANCE or 0. PX4 instance n also listens on UDP 14580 + n and
  /// 18570 + n: fleets 40 apart collide (one's 14540 + n is the other's 14580 + n). PX4
  /// instances must be 0..9: above, PX4 sends every offboard link to 14549 (start() refuses).
  int first_instance = -1;
  /// A camera configured the way a user sets one up for pictures: ArduPilot CAM1_TYPE 1
  /// (servo-triggered; set with PARAM_SET and the instance restarted in wait_ready(), as its
  /// camera backend exists only from boot, and read back once ready), PX4 TRIG_MODE 1 (camera_trigger on command;
  /// SITL's TRIG_INTERFACE is 3, MAVLink). false: stock parameters, no camera.
  bool camera = false;
  /// A battery that drains at a rate the test chooses, so a mission that waits for it
  /// (patrol's `Lead.Battery() > 98`) ends within a test's time: PX4 SIM_BAT_DRAIN = this
  /// (seconds of the vehicle's time from 100 % to 0 % while armed; SIM_BAT_MIN_PCT stays
  /// 50); ArduPilot BATT_CAPACITY = the mAh the SITL copter's hover current (measured,
  /// sitl.cpp) uses up in this time (its remaining % counts consumed mAh against
  /// BATT_CAPACITY). 0: the stock models (PX4 60 s, ArduPilot 3300 mAh).
  double battery_drain_s = 0;
  /// PX4: an instance that sent no HEARTBEAT this long after start() is killed and started
  /// again, once (a start-up that stopped; sitl.cpp).
  double silent_boot_s = 20;
};

/// Where a point of the earth (degE7) lies in the mission frame of the test fleets (x east, y
/// north of the origin the instances' homes are placed from), on the WGS-84 ellipsoid.
void mission_xy(int32_t lat_e7, int32_t lon_e7, double& x, double& y);

class SitlFleet {
 public:
  /// The binary from the environment, or "" when the variable is unset or names no file.
  static std::string binary(Autopilot autopilot);
  /// Why the SITL tests skip, and how to run them.
  static std::string skip_message(Autopilot autopilot);

  explicit SitlFleet(SitlOptions options);
  ~SitlFleet();
  SitlFleet(const SitlFleet&) = delete;
  SitlFleet& operator=(const SitlFleet&) = delete;

  /// Starts every instance; false with `error` set when one cannot be started.
  bool start(std::string& error);
  /// Waits (wall time, bounded) until every instance passes its pre-arm checks and reports a
  /// position: the state in which a pilot would arm. ArduPilot: then SIM_SPEEDUP is set to
  /// the options' speed-up (the boot ran faster). False with the instances not ready.
  bool wait_ready(double timeout_s, std::string& error);
  /// Sets one parameter of a ready instance the way a ground station does (PARAM_SET until
  /// the PARAM_VALUE echo carries the value; PX4's integers travel bytewise in the float).
  /// Call it before eamos opens the instance's port. False with `error` set on timeout.
  /// `as_ground_station` false: its HEARTBEAT does not announce a GCS (PX4 would then send
  /// STATUSTEXT on that port for 2.5 s, to whoever comes next: a test of what eamos itself
  /// gets must not be helped by it).
  bool set_param(int i, const std::string& name, float value, uint8_t type, double timeout_s, std::string& error,
                 bool as_ground_station = true);
  /// What the autopilot holds as its fence, read the way a ground station does
  /// (MISSION_REQUEST_LIST of type FENCE, then each item), and the values of `params` (PX4's
  /// integers read bytewise when `integer` names them). Call it when eamos has closed the
  /// port. False with `error` set on timeout.
  bool read_fence(int i, const std::vector<std::string>& params, const std::vector<std::string>& integer,
                  double timeout_s, std::vector<eamos::mavlink::MissionItemInt>& items,
                  std::map<std::string, double>& values, std::string& error);
  /// Kills one instance at once (a vehicle whose link is lost mid-flight).
  void kill_instance(int i);
  /// Stops one instance's process (SIGSTOP) as a start-up that hangs: it sends nothing more
  /// until it is killed.
  void hang_instance(int i);
  /// SIGTERM, then SIGKILL after a grace period, for every instance still running.
  void stop();

  int size() const { return static_cast<int>(instances_.size()); }
  Autopilot autopilot() const { return options_.autopilot; }
  /// The `connection:` URL that reaches instance i, as a fleet file writes it.
  std::string connection(int i) const;
  /// PX4 derives its system id from the instance number; ArduPilot is told the same one.
  int sysid(int i) const { return instance_number(i) + 1; }
  /// The last lines the instance printed, for failure messages.
  std::string log_tail(int i) const;

 private:
  struct Instance {
    pid_t pid = -1;
    std::string dir;
  };
  bool start_one(int i, std::string& error);
  bool spawn(int i, std::string& error);
  /// Stops instance i and starts it again in its folder, as a power cycle.
  bool restart_instance(int i, std::string& error);
  /// PX4 only: the fleet started more than SitlOptions::silent_boot_s ago.
  bool silent_too_long() const;
  /// Kills instance i, which never sent a HEARTBEAT, and starts it again in its folder.
  bool restart_silent_instance(int i, std::string& error);
  int instance_number(int i) const { return first_instance_ + i; }
  std::vector<std::string> command_line(int i, const std::string& binary) const;
  double boot_speedup() const;
  void prepare_px4_bin(const std::string& dir, const std::string& binary) const;
  bool set_up_ardupilot_camera(int i, double deadline, std::string& error);
  bool wait_all_ready(double deadline, bool camera, std::string& error, std::vector<int>* no_camera = nullptr);
  bool wait_ready_with_camera(double deadline, std::string& error);

  SitlOptions options_;
  int first_instance_ = 0;
  double started_s_ = 0;  ///< steady clock at start(), for EAMOS_SITL_VERBOSE's timings
  std::vector<Instance> instances_;
};

/// One position report of a vehicle, as a ground station beside eamos sees it.
struct VehicleSample {
  double wall_s = 0;            ///< steady clock, seconds
  double north = 0, east = 0, down = 0;  ///< LOCAL_POSITION_NED, m from the vehicle's home
  double speed = 0;             ///< horizontal, m/s
  uint32_t custom_mode = 0;     ///< the flight mode of the newest HEARTBEAT before it
  bool armed = false;           ///< the armed flag of the newest HEARTBEAT before it
  int32_t lat_e7 = 0, lon_e7 = 0;  ///< the newest GLOBAL_POSITION_INT before it
  int32_t orbit_lat_e7 = 0, orbit_lon_e7 = 0;  ///< the newest ORBIT_EXECUTION_STATUS's centre (PX4), else 0
  /// Where the vehicle really was: the newest HIL_STATE_QUATERNION (PX4 SIH's ground truth), else 0.
  int32_t true_lat_e7 = 0, true_lon_e7 = 0;
  /// Heading, rad from north: the newest ATTITUDE (the vehicle's estimate) and the newest
  /// HIL_STATE_QUATERNION (PX4 SIH's truth, else 0).
  double yaw = 0, true_yaw = 0;
};

/// A second ground station on one instance (ArduPilot SERIAL1, TCP 5762 + 10 n; PX4's GCS
/// link, UDP 18570 + n): records what the vehicle does, independently of eamos' link, so a
/// test can judge the flight from the vehicle's own telemetry.
class SitlWatch {
 public:
  SitlWatch(const SitlFleet& fleet, int i);
  ~SitlWatch();
  SitlWatch(const SitlWatch&) = delete;
  SitlWatch& operator=(const SitlWatch&) = delete;
  /// "" when the link is open, else why not.
  const std::string& error() const { return error_; }
  std::vector<VehicleSample> samples() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
  std::string error_;
};

}  // namespace eamos_test
