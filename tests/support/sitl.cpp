#include "support/sitl.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <mutex>
#include <sstream>
#include <thread>

#include "mavlink/enums.h"
#include "mavlink/link.h"
#include "mavlink/messages.h"
#include "mavlink/payloads.h"
#include "fleet/link_url.h"

namespace eamos_test {
namespace fs = std::filesystem;
namespace ml = eamos::mavlink;

namespace {

// Every fleet is placed around one geographic origin (PX4's default SIH location): the
// mission frame's (0, 0) is there, x east and y north.
constexpr double kOriginLat = 47.397742;
constexpr double kOriginLon = 8.545594;
constexpr double kOriginAlt = 488.0;
constexpr uint32_t kPrearmCheck = 0x10000000;  // MAV_SYS_STATUS_PREARM_CHECK
// ArduCopter SITL's battery current in flight (`--model +`, stock copter.parm), measured on
// this binary: with the stock BATT_CAPACITY 3300 mAh its remaining % fell by 1 every 4.1 s
// hovering at 10 m (and as fast during the takeoff), 33 mAh per 4.1 s. Turns a drain time
// into BATT_CAPACITY.
constexpr double kArduCopterSitlHoverA = 29;
// ArduCopter SITL boots (GPS lock, EKF alignment, the camera set-up's second boot) at this
// simulation speed, and wait_ready() sets SIM_SPEEDUP back to the flight's speed-up before
// eamos connects: standing on the ground, nothing a test judges depends on how fast the
// boot ran (MAVProxy's sitl_autospeedup does the same). Measured (EAMOS_SITL_VERBOSE=1,
// three instances on 2 cores, load average 7): start to ready 8.3 s at 5x, 2.7 s at 20x,
// 2.0 s at 50x; 20x leaves the machine's other work some CPU.
constexpr double kArduPilotBootSpeedup = 20;

double now_s() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

// Metres per degree on the WGS-84 ellipsoid at a latitude, accurate to centimetres over the
// few hundred metres a test fleet spans.
void metres_per_degree(double lat_deg, double& per_lat, double& per_lon) {
  double p = lat_deg * M_PI / 180.0;
  per_lat = 111132.92 - 559.82 * std::cos(2 * p) + 1.175 * std::cos(4 * p);
  per_lon = 111412.84 * std::cos(p) - 93.5 * std::cos(3 * p);
}

// Where a fixture's wall time goes (boot, camera set-up, stop), one line per step, for the
// suite's time budget (docs/adapters.md, "SITL tests"). Always on stderr, which ctest shows
// only for a failed test: a failed case can spend far longer outside its flight than in it,
// and this says where.
void report_time(const std::string& step, double since_s) {
  std::fprintf(stderr, "[sitl] %s: %.2f s\n", step.c_str(), now_s() - since_s);
}

void geographic_home(const SitlHome& h, double& lat, double& lon) {
  double per_lat, per_lon;
  metres_per_degree(kOriginLat, per_lat, per_lon);
  lat = kOriginLat + h.y / per_lat;
  lon = kOriginLon + h.x / per_lon;
}

}  // namespace

void mission_xy(int32_t lat_e7, int32_t lon_e7, double& x, double& y) {
  double per_lat, per_lon;
  metres_per_degree(kOriginLat, per_lat, per_lon);
  y = (lat_e7 / 1e7 - kOriginLat) * per_lat;
  x = (lon_e7 / 1e7 - kOriginLon) * per_lon;
}

namespace {

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

const char* variable(Autopilot a) {
  return a == Autopilot::ardupilot ? "EAMOS_ARDUPILOT_SITL" : "EAMOS_PX4_SITL";
}

// Waits for a child told to stop until `deadline`, then kills it: a test must never leave
// one behind.
void reap(pid_t pid, double deadline) {
  while (waitpid(pid, nullptr, WNOHANG) == 0) {
    if (now_s() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
      return;
    }
    usleep(20000);
  }
}

}  // namespace

std::string SitlFleet::binary(Autopilot autopilot) {
  const char* path = std::getenv(variable(autopilot));
  if (!path || !*path) return "";
  std::error_code ec;
  return fs::is_regular_file(path, ec) ? std::string(path) : std::string();
}

std::string SitlFleet::skip_message(Autopilot autopilot) {
  const char* path = std::getenv(variable(autopilot));
  std::string what = autopilot == Autopilot::ardupilot
                         ? "an ArduCopter SITL binary (arducopter, with copter.parm beside it)"
                         : "a PX4 SITL binary built with SIH (bin/px4, with etc/ beside bin/)";
  std::string state = path && *path ? std::string(variable(autopilot)) + "=" + path + " names no file"
                                    : std::string(variable(autopilot)) + " is not set";
  return state + ": set it to " + what +
         "; .ci/run sets it when ../shared/sitl exists (docs/adapters.md, 'SITL tests')";
}

SitlFleet::SitlFleet(SitlOptions options) : options_(std::move(options)) {
  first_instance_ = options_.first_instance;
  if (first_instance_ < 0) {
    const char* env = std::getenv("EAMOS_SITL_FIRST_INSTANCE");
    first_instance_ = env ? std::atoi(env) : 0;
    if (first_instance_ < 0 || first_instance_ > 200) first_instance_ = 0;
  }
}

SitlFleet::~SitlFleet() { stop(); }

bool SitlFleet::start(std::string& error) {
  std::string bin = binary(options_.autopilot);
  if (bin.empty()) {
    error = skip_message(options_.autopilot);
    return false;
  }
  // px4-rc.mavlink: "[ $px4_instance -gt 9 ] && udp_offboard_port_remote=14549", so every
  // instance above 9 sends its offboard link to one port and the fleet's udp://:14540+n hears
  // nothing (seen as "not ready: no HEARTBEAT" after the whole wait).
  int last = instance_number(static_cast<int>(options_.homes.size()) - 1);
  if (options_.autopilot == Autopilot::px4 && last > 9) {
    error = "PX4 SITL instance " + std::to_string(last) + " would send to UDP 14549, not " +
            std::to_string(14540 + last) + " (instances above 9 share that port): set EAMOS_SITL_FIRST_INSTANCE to " +
            std::to_string(10 - static_cast<int>(options_.homes.size())) + " or less";
    return false;
  }
  started_s_ = now_s();
  for (int i = 0; i < static_cast<int>(options_.homes.size()); ++i)
    if (!start_one(i, error)) return false;
  return true;
}

// ArduPilot's --speedup applies at every start (it overrides the SIM_SPEEDUP saved in the
// instance's eeprom.bin), so the camera set-up's restart boots fast too.
double SitlFleet::boot_speedup() const {
  return std::max(options_.speedup, kArduPilotBootSpeedup);
}

std::vector<std::string> SitlFleet::command_line(int i, const std::string& bin) const {
  double lat, lon;
  geographic_home(options_.homes[i], lat, lon);
  if (options_.autopilot == Autopilot::ardupilot) {
    std::string parm = (fs::path(bin).parent_path() / "copter.parm").string();
    std::vector<std::string> args = {
        bin, "-I", std::to_string(instance_number(i)), "--model", "+", "--speedup", fixed(boot_speedup(), 2),
        "--sysid", std::to_string(sysid(i)), "--home", fixed(lat, 8) + "," + fixed(lon, 8) + "," + fixed(kOriginAlt, 1) + ",0",
        "--defaults", parm, "--serial0", "tcp:0"};
    // -w wipes the saved parameters. The folder is new and empty, so there is nothing to wipe
    // at the first boot, and the camera set-up restarts the instance with the same arguments
    // to keep the CAM1_TYPE it saved (set_up_ardupilot_camera()).
    if (!options_.camera) args.insert(args.end() - 2, "-w");
    return args;
  }
  std::string etc = (fs::path(bin).parent_path().parent_path() / "etc").string();
  return {instances_[i].dir + "/bin/px4", "-i", std::to_string(instance_number(i)), "-d", etc};
}

// PX4's start-up script runs its modules as `px4-NAME` commands from PATH, links to the one
// px4 binary. A read-only copy (../shared) may hold them as plain files, so each instance
// gets its own folder of links.
void SitlFleet::prepare_px4_bin(const std::string& dir, const std::string& bin) const {
  fs::path own = fs::path(dir) / "bin";
  fs::create_directories(own);
  fs::path real = fs::canonical(bin);
  fs::create_symlink(real, own / "px4");
  for (const auto& e : fs::directory_iterator(real.parent_path())) {
    std::string name = e.path().filename().string();
    if (name.rfind("px4-", 0) != 0) continue;
    if (name == "px4-alias.sh") fs::copy_file(e.path(), own / name);
    else fs::create_symlink(real, own / name);
  }
}

bool SitlFleet::start_one(int i, std::string& error) {
  std::string bin = binary(options_.autopilot);
  char tmpl[] = "/tmp/eamos-sitl-XXXXXX";
  if (!mkdtemp(tmpl)) {
    error = "cannot create a folder for SITL instance " + std::to_string(i);
    return false;
  }
  Instance inst;
  inst.dir = tmpl;
  instances_.push_back(inst);
  if (options_.autopilot == Autopilot::px4) prepare_px4_bin(inst.dir, bin);
  return spawn(i, error);
}

// Starts instance i's process in its folder (again, after restart_instance()'s stop: it
// keeps what the instance saved there).
bool SitlFleet::spawn(int i, std::string& error) {
  const Instance& inst = instances_.at(i);
  std::vector<std::string> args = command_line(i, binary(options_.autopilot));
  double lat, lon;
  geographic_home(options_.homes[i], lat, lon);
  std::string log = inst.dir + "/out.log";
  pid_t pid = fork();
  if (pid < 0) {
    error = "fork failed for SITL instance " + std::to_string(i);
    return false;
  }
  if (pid == 0) {
    // The child: its own folder and log, and gone when the test process is (PX4 would
    // otherwise outlive a crashed test; ArduPilot watches its parent by itself).
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (chdir(inst.dir.c_str()) != 0) _exit(127);
    int out = open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    int in = open("/dev/null", O_RDONLY);
    if (out < 0 || in < 0) _exit(127);
    dup2(in, 0);
    dup2(out, 1);
    dup2(out, 2);
    if (options_.autopilot == Autopilot::px4) {
      setenv("PX4_SYS_AUTOSTART", "10040", 1);
      setenv("PX4_SIMULATOR", "sihsim", 1);
      setenv("PX4_HOME_LAT", fixed(lat, 8).c_str(), 1);
      setenv("PX4_HOME_LON", fixed(lon, 8).c_str(), 1);
      setenv("PX4_HOME_ALT", fixed(kOriginAlt, 1).c_str(), 1);
      setenv("PX4_SIM_SPEED_FACTOR", fixed(options_.speedup, 2).c_str(), 1);
      // rcS sets parameters from PX4_PARAM_<name> before it starts camera_trigger.
      if (options_.camera) setenv("PX4_PARAM_TRIG_MODE", "1", 1);
      // battery_simulator drains SIM_BAT_DRAIN seconds (vehicle time) from full to empty.
      if (options_.battery_drain_s > 0)
        setenv("PX4_PARAM_SIM_BAT_DRAIN", fixed(options_.battery_drain_s, 1).c_str(), 1);
      std::string path = inst.dir + "/bin:" + (std::getenv("PATH") ? std::getenv("PATH") : "/usr/bin:/bin");
      setenv("PATH", path.c_str(), 1);
    }
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  instances_[i].pid = pid;
  return true;
}

std::string SitlFleet::connection(int i) const {
  if (options_.autopilot == Autopilot::ardupilot) return "tcp://127.0.0.1:" + std::to_string(5760 + 10 * instance_number(i));
  return "udp://:" + std::to_string(14540 + instance_number(i));
}

std::string SitlFleet::log_tail(int i) const {
  std::ifstream in(instances_.at(i).dir + "/out.log");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  std::string out;
  for (std::size_t k = lines.size() > 15 ? lines.size() - 15 : 0; k < lines.size(); ++k) out += lines[k] + "\n";
  return out;
}

void SitlFleet::kill_instance(int i) {
  Instance& inst = instances_.at(i);
  if (inst.pid <= 0) return;
  kill(inst.pid, SIGKILL);
  waitpid(inst.pid, nullptr, 0);
  inst.pid = -1;
}

void SitlFleet::stop() {
  const double began = now_s();
  for (auto& inst : instances_)
    if (inst.pid > 0) kill(inst.pid, SIGTERM);
  double deadline = now_s() + 5.0;
  for (auto& inst : instances_) {
    if (inst.pid <= 0) continue;
    reap(inst.pid, deadline);
    inst.pid = -1;
  }
  for (auto& inst : instances_) {
    std::error_code ec;
    if (!std::getenv("EAMOS_KEEP_SITL_DIRS")) fs::remove_all(inst.dir, ec);
  }
  if (!instances_.empty()) report_time("stop", began);
  instances_.clear();
}

namespace {

// What one instance has shown so far, filled on its probe link's thread.
struct Readiness {
  std::mutex mutex;
  std::condition_variable changed;
  bool heartbeat = false;
  bool prearm_ok = false;
  bool position = false;
  bool ekf_uses_gps = false;  ///< ArduPilot: "EKF3 IMU0 is using GPS"; GUIDED needs it
  bool need_ekf_text = false;
  bool need_camera = false;  ///< ArduPilot with a camera: CAM1_TYPE must read back 1
  std::optional<float> cam1_type;
  bool camera_ok() const { return !need_camera || cam1_type == 1.0f; }
  bool booted() const { return heartbeat && prearm_ok && position && (ekf_uses_gps || !need_ekf_text); }
  bool ready() const { return booted() && camera_ok(); }
  /// Ready, but CAM1_TYPE was read and is not 1: the camera did not take.
  bool ready_but_camera() const { return booted() && cam1_type && !camera_ok(); }
  std::string missing() const {
    if (!heartbeat) return "no HEARTBEAT";
    if (!camera_ok())
      return cam1_type ? "CAM1_TYPE reads " + std::to_string(*cam1_type) + " after boot, not 1 (no camera)"
                       : "no answer to PARAM_REQUEST_READ CAM1_TYPE";
    if (!prearm_ok) return "pre-arm checks not passed (SYS_STATUS)";
    if (!position) return "no position (GLOBAL_POSITION_INT)";
    return "the EKF does not use GPS yet (no STATUSTEXT 'is using GPS')";
  }
};

void on_probe_frame(Readiness& r, uint8_t sysid, const ml::Frame& f) {
  if (f.sysid != sysid || f.compid != 1) return;
  std::lock_guard lock(r.mutex);
  if (ml::unpack_heartbeat(f.message)) r.heartbeat = true;
  // PX4 reports the pre-arm bit only in `health` (not in `present`), and only once its
  // health checks pass; ArduPilot sets it in both. So the health bit alone decides.
  if (auto s = ml::unpack_sys_status(f.message)) r.prearm_ok = (s->sensors_health & kPrearmCheck) != 0;
  if (auto g = ml::unpack_global_position_int(f.message)) r.position = g->lat != 0 || g->lon != 0;
  if (auto p = ml::unpack_param_value(f.message))
    if (p->param_id == "CAM1_TYPE") r.cam1_type = p->param_value;
  if (auto t = ml::unpack_statustext(f.message))
    if (t->text.find("is using GPS") != std::string::npos) r.ekf_uses_gps = true;
  r.changed.notify_all();
}

// A ground station's HEARTBEAT: PX4 sends its GCS link's streams to whoever sent one.
void send_gcs_heartbeat(ml::Link& link, ml::Encoder& encoder) {
  ml::Heartbeat hb;
  hb.type = 6;       // MAV_TYPE_GCS
  hb.autopilot = 8;  // MAV_AUTOPILOT_INVALID
  link.send(encoder.encode(ml::pack(hb)));
}

void send_command(ml::Link& link, ml::Encoder& encoder, uint8_t sysid, uint16_t command, float param0,
                  float param1 = 0) {
  ml::CommandLong c;
  c.target_system = sysid;
  c.target_component = 1;
  c.command = command;
  c.param[0] = param0;
  c.param[1] = param1;
  link.send(encoder.encode(ml::pack(c)));
}

// Asks for the two messages readiness is judged by, at 2 Hz, announcing a ground station;
// `camera`: and for CAM1_TYPE (ArduPilot), which must be 1.
void ask_for_status(ml::Link& link, ml::Encoder& encoder, uint8_t sysid, bool camera) {
  send_gcs_heartbeat(link, encoder);
  for (uint32_t id : {ml::msg::SYS_STATUS, ml::msg::GLOBAL_POSITION_INT})
    send_command(link, encoder, sysid, ml::cmd::SET_MESSAGE_INTERVAL, static_cast<float>(id), 500000);
  if (camera) link.send(encoder.encode(ml::pack(ml::ParamRequestRead{sysid, 1, "CAM1_TYPE", -1})));
}

// What set_param has seen of one instance, filled on the link's thread.
struct ParamEchoes {
  std::mutex mutex;
  std::condition_variable changed;
  std::map<std::string, float> params;  ///< PARAM_VALUEs by name
};

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Waits (bounded by `deadline`, resending `ask` every half second) until `done` holds.
bool wait_for(ParamEchoes& cs, double deadline, const std::function<void()>& ask, const std::function<bool()>& done) {
  std::unique_lock lock(cs.mutex);
  while (!done()) {
    if (now_s() > deadline) return false;
    lock.unlock();
    ask();
    lock.lock();
    cs.changed.wait_for(lock, std::chrono::milliseconds(500), done);
  }
  return true;
}

}  // namespace

// ArduPilot creates its camera backend only at boot. CAM1_TYPE 1 in the --defaults file is
// read back as 0 after boot on this 4.7 build, and a reboot by MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN
// (SITL re-executes itself in place, with its own arguments: `-w`, "wipe the saved
// parameters", included) lost the camera in about half the runs, and once here the reboot
// did not happen at all. So the camera is set as a user sets it, PARAM_SET CAM1_TYPE 1
// (saved to the instance's eeprom.bin), and the fixture power-cycles the instance itself:
// stopped, then started again in its folder, without `-w` (command_line()). wait_ready()
// then reads CAM1_TYPE back from the new boot.
bool SitlFleet::set_up_ardupilot_camera(int i, double deadline, std::string& error) {
  // The PARAM_VALUE echo comes before ArduPilot's IO thread has written the parameter to
  // eeprom.bin; stopped before that, the instance boots without it. So the restart waits for
  // the file to change (nothing else is saved a few seconds after boot).
  const std::string eeprom = instances_.at(i).dir + "/eeprom.bin";
  const std::string before = read_file(eeprom);
  const double began = now_s();
  if (!set_param(i, "CAM1_TYPE", 1, ml::param_type::INT8, deadline - now_s(), error)) return false;
  report_time("instance " + std::to_string(i) + " CAM1_TYPE echoed", began);
  const double saved_by = std::min(deadline, now_s() + 10.0);
  while (read_file(eeprom) == before) {
    if (now_s() > saved_by) {
      error = "SITL instance " + std::to_string(i) + ": CAM1_TYPE 1 echoed but eeprom.bin did not change\n" + log_tail(i);
      return false;
    }
    usleep(20000);
  }
  report_time("instance " + std::to_string(i) + " eeprom.bin saved", began);
  const double restarting = now_s();
  bool restarted = restart_instance(i, error);
  report_time("instance " + std::to_string(i) + " stopped and started again", restarting);
  return restarted;
}

bool SitlFleet::restart_instance(int i, std::string& error) {
  Instance& inst = instances_.at(i);
  kill(inst.pid, SIGTERM);
  reap(inst.pid, now_s() + 5.0);
  inst.pid = -1;
  return spawn(i, error);
}

// PX4 SITL's start-up can stop in its start-up script (its log ends after the ground
// station's MAVLink instance starts) and send nothing at all, where a boot sends its first
// HEARTBEAT within 5 s. Such an instance is killed and started again, once, after
// silent_boot_s, rather than failing its test at the end of wait_ready()'s timeout.
bool SitlFleet::silent_too_long() const {
  return options_.autopilot == Autopilot::px4 && now_s() - started_s_ > options_.silent_boot_s;
}

void SitlFleet::hang_instance(int i) {
  if (instances_.at(i).pid > 0) kill(instances_.at(i).pid, SIGSTOP);
}

bool SitlFleet::restart_silent_instance(int i, std::string& error) {
  std::cout << "[sitl] PX4 instance " << i << " sent no HEARTBEAT within " << options_.silent_boot_s
            << " s of its start: killed and started again. Its log ended with:\n"
            << log_tail(i) << std::flush;
  kill_instance(i);
  return spawn(i, error);
}

bool SitlFleet::wait_ready(double timeout_s, std::string& error) {
  const double deadline = now_s() + timeout_s;
  if (!wait_ready_with_camera(deadline, error)) return false;
  report_time("start to ready", started_s_);
  if (options_.autopilot == Autopilot::ardupilot && boot_speedup() != options_.speedup) {
    const double slowing = now_s();
    for (int i = 0; i < size(); ++i)
      if (!set_param(i, "SIM_SPEEDUP", static_cast<float>(options_.speedup), ml::param_type::REAL32,
                     deadline - now_s(), error))
        return false;
    report_time("SIM_SPEEDUP back to the flight's", slowing);
  }
  // Remaining % is consumed mAh against BATT_CAPACITY: the capacity that lasts
  // battery_drain_s at the SITL copter's hover current (PX4: SIM_BAT_DRAIN at start).
  if (options_.battery_drain_s > 0 && options_.autopilot == Autopilot::ardupilot)
    for (int i = 0; i < size(); ++i) {
      float capacity = std::round(static_cast<float>(kArduCopterSitlHoverA * options_.battery_drain_s / 3.6));
      if (!set_param(i, "BATT_CAPACITY", capacity, ml::param_type::INT32, deadline - now_s(), error)) return false;
    }
  return true;
}

bool SitlFleet::wait_ready_with_camera(double deadline, std::string& error) {
  if (!options_.camera || options_.autopilot != Autopilot::ardupilot) return wait_all_ready(deadline, false, error);
  // The camera is set once the instance has booted completely (ready): a PARAM_SET during
  // its start-up was overwritten by ArduPilot's own start-up (CAM1_TYPE 0 after the restart).
  // Checked on the new boot; set again if it still did not take.
  if (!wait_all_ready(deadline, false, error)) return false;
  report_time("start to first boot ready", started_s_);
  std::vector<int> todo;
  for (int i = 0; i < size(); ++i) todo.push_back(i);
  for (int attempt = 0; attempt < 3 && !todo.empty(); ++attempt) {
    for (int i : todo)
      if (!set_up_ardupilot_camera(i, deadline, error)) return false;
    todo.clear();
    const double rebooting = now_s();
    if (!wait_all_ready(deadline, true, error, &todo)) return false;
    report_time("restarted instances ready with the camera", rebooting);
  }
  if (todo.empty()) return true;
  error = "SITL instance " + std::to_string(todo.front()) + ": CAM1_TYPE still 0 after three restarts\n" +
          log_tail(todo.front());
  return false;
}

// PX4 puts an integer parameter's bits in PARAM_VALUE's float (the MAVLink "bytewise"
// encoding); ArduPilot sends the number as a float.
static float wire_param(Autopilot autopilot, float value, uint8_t type) {
  if (autopilot != Autopilot::px4 || type == ml::param_type::REAL32) return value;
  int32_t as_int = static_cast<int32_t>(value);
  float wire = 0;
  std::memcpy(&wire, &as_int, sizeof wire);
  return wire;
}

bool SitlFleet::set_param(int i, const std::string& name, float value, uint8_t type, double timeout_s,
                          std::string& error, bool as_ground_station) {
  ParamEchoes cs;
  const uint8_t vehicle = static_cast<uint8_t>(sysid(i));
  ml::OpenResult opened = ml::Link::open(
      *eamos::fleet::parse_link_url(connection(i)).endpoint,
      [&cs, vehicle](ml::Frame f) {
        if (f.sysid != vehicle || f.compid != 1) return;
        auto p = ml::unpack_param_value(f.message);
        if (!p) return;
        std::lock_guard lock(cs.mutex);
        cs.params[p->param_id] = p->param_value;
        cs.changed.notify_all();
      },
      0.2);
  if (!opened.link) {
    error = "cannot set " + name + " on SITL instance " + std::to_string(i) + ": " + opened.error;
    return false;
  }
  const float wire = wire_param(options_.autopilot, value, type);
  ml::Encoder encoder{250, 190, 0};
  auto send_set = [&] {
    ml::Heartbeat hb;
    hb.type = as_ground_station ? 6 : 18;  // MAV_TYPE_GCS or MAV_TYPE_ONBOARD_CONTROLLER
    hb.autopilot = 8;  // MAV_AUTOPILOT_INVALID
    opened.link->send(encoder.encode(ml::pack(hb)));
    opened.link->send(encoder.encode(ml::pack(ml::ParamSet{vehicle, 1, name, wire, type})));
  };
  auto echoed = [&] {
    auto it = cs.params.find(name);
    return it != cs.params.end() && std::memcmp(&it->second, &wire, sizeof wire) == 0;
  };
  bool ok = wait_for(cs, now_s() + timeout_s, send_set, echoed);
  opened.link.reset();
  if (!ok) error = "SITL instance " + std::to_string(i) + ": no PARAM_VALUE " + name + " = " + fixed(value, 2) + "\n" + log_tail(i);
  return ok;
}

namespace {

// What read_fence collects from the vehicle's link thread.
struct FenceRead {
  std::mutex mutex;
  std::condition_variable changed;
  int count = -1;  ///< the MISSION_COUNT, -1 before it
  std::map<uint16_t, ml::MissionItemInt> items;
  std::map<std::string, float> params;
};

// Asks for what has not come yet: the count, the items, the parameters.
void ask_fence(FenceRead& r, uint8_t vehicle, const std::vector<std::string>& params,
               const std::function<void(const ml::Message&)>& send) {
  ml::Heartbeat hb;
  hb.type = 6;       // MAV_TYPE_GCS
  hb.autopilot = 8;  // MAV_AUTOPILOT_INVALID
  send(ml::pack(hb));
  std::unique_lock lock(r.mutex);
  int count = r.count;
  std::vector<uint16_t> missing;
  for (int k = 0; k < count; ++k)
    if (!r.items.contains(static_cast<uint16_t>(k))) missing.push_back(static_cast<uint16_t>(k));
  std::vector<std::string> unread;
  for (const std::string& p : params)
    if (!r.params.contains(p)) unread.push_back(p);
  lock.unlock();
  if (count < 0) send(ml::pack(ml::MissionRequestList{vehicle, 1, ml::mission_type::FENCE}));
  for (uint16_t k : missing) send(ml::pack(ml::MissionRequest{vehicle, 1, k, ml::mission_type::FENCE}));
  for (const std::string& p : unread) send(ml::pack(ml::ParamRequestRead{vehicle, 1, p, -1}));
}

}  // namespace

bool SitlFleet::read_fence(int i, const std::vector<std::string>& params, const std::vector<std::string>& integer,
                           double timeout_s, std::vector<ml::MissionItemInt>& items,
                           std::map<std::string, double>& values, std::string& error) {
  FenceRead r;
  const uint8_t vehicle = static_cast<uint8_t>(sysid(i));
  ml::OpenResult opened = ml::Link::open(
      *eamos::fleet::parse_link_url(connection(i)).endpoint,
      [&r, vehicle](ml::Frame f) {
        if (f.sysid != vehicle || f.compid != 1) return;
        std::lock_guard lock(r.mutex);
        if (auto c = ml::unpack_mission_count(f.message); c && c->mission_type == ml::mission_type::FENCE) r.count = c->count;
        if (auto it = ml::unpack_mission_item_int(f.message); it && it->mission_type == ml::mission_type::FENCE)
          r.items[it->seq] = *it;
        if (auto p = ml::unpack_param_value(f.message)) r.params[p->param_id] = p->param_value;
        r.changed.notify_all();
      },
      0.2);
  if (!opened.link) {
    error = "cannot read the fence of SITL instance " + std::to_string(i) + ": " + opened.error;
    return false;
  }
  ml::Encoder encoder{250, 190, 0};
  auto send = [&](const ml::Message& m) { opened.link->send(encoder.encode(m)); };
  auto done = [&] {
    if (r.count < 0 || static_cast<int>(r.items.size()) < r.count) return false;
    for (const std::string& p : params)
      if (!r.params.contains(p)) return false;
    return true;
  };
  const double deadline = now_s() + timeout_s;
  bool ok = false;
  {
    std::unique_lock lock(r.mutex);
    while (!(ok = done()) && now_s() < deadline) {
      lock.unlock();
      ask_fence(r, vehicle, params, send);
      lock.lock();
      r.changed.wait_for(lock, std::chrono::milliseconds(300), done);
    }
  }
  if (ok) send(ml::pack(ml::MissionAck{vehicle, 1, ml::mission_result::ACCEPTED, ml::mission_type::FENCE}));
  opened.link.reset();
  if (!ok) {
    error = "SITL instance " + std::to_string(i) + ": no complete fence read back (count " + std::to_string(r.count) +
            ", " + std::to_string(r.items.size()) + " items)\n" + log_tail(i);
    return false;
  }
  items.clear();
  for (auto& [seq, item] : r.items) items.push_back(item);
  for (const std::string& p : params) {
    bool bytewise = options_.autopilot == Autopilot::px4 && std::find(integer.begin(), integer.end(), p) != integer.end();
    int32_t v = 0;
    std::memcpy(&v, &r.params[p], sizeof v);
    values[p] = bytewise ? v : r.params[p];
  }
  return true;
}

// Short-lived links of the test's own, one per instance and all open at once (a STATUSTEXT
// is sent once, to whoever is connected then); closed before eamos opens the same ports.
// `camera`: CAM1_TYPE must read 1 too; the instances where it reads 0 go to `no_camera`
// (then the others are still waited for and true is returned), or fail when it is null.
bool SitlFleet::wait_all_ready(double deadline, bool camera, std::string& error, std::vector<int>* no_camera) {
  std::vector<std::unique_ptr<Readiness>> state;
  std::vector<std::unique_ptr<ml::Link>> links;
  for (int i = 0; i < size(); ++i) {
    state.push_back(std::make_unique<Readiness>());
    state.back()->need_ekf_text = options_.autopilot == Autopilot::ardupilot;
    state.back()->need_camera = camera;
    Readiness* r = state.back().get();
    uint8_t vehicle = static_cast<uint8_t>(sysid(i));
    // ArduPilot opens its TCP port a moment after it starts: try again until the deadline.
    ml::OpenResult opened;
    while (!opened.link && now_s() < deadline) {
      opened = ml::Link::open(*eamos::fleet::parse_link_url(connection(i)).endpoint,
                              [r, vehicle](ml::Frame f) { on_probe_frame(*r, vehicle, f); }, 0.2);
      if (!opened.link) usleep(100000);
    }
    if (!opened.link) {
      error = "cannot watch SITL instance " + std::to_string(i) + ": " + opened.error;
      return false;
    }
    links.push_back(std::move(opened.link));
  }
  ml::Encoder encoder{250, 190, 0};
  std::vector<bool> restarted(size(), false);
  for (int i = 0; i < size(); ++i) {
    Readiness& r = *state[i];
    std::unique_lock lock(r.mutex);
    auto settled = [&] { return r.ready() || (no_camera && r.ready_but_camera()); };
    while (!settled()) {
      if (now_s() > deadline) {
        error = "SITL instance " + std::to_string(i) + " not ready: " + r.missing() + "\n" + log_tail(i);
        return false;
      }
      if (!r.heartbeat && !restarted[i] && silent_too_long()) {
        restarted[i] = true;
        lock.unlock();
        if (!restart_silent_instance(i, error)) return false;
        lock.lock();
        continue;
      }
      lock.unlock();
      for (int k = 0; k < size(); ++k)
        ask_for_status(*links[k], encoder, static_cast<uint8_t>(sysid(k)), state[k]->need_camera);
      lock.lock();
      r.changed.wait_for(lock, std::chrono::milliseconds(500), settled);
    }
    if (!r.ready()) no_camera->push_back(i);
  }
  return true;
}

// --- a second ground station ---------------------------------------------------------------

namespace {
// The watch's HEARTBEAT poll: 20 ms of wall clock is 0.1 s of the vehicle's at --speedup 5.
constexpr auto kWatchPoll = std::chrono::milliseconds(20);
constexpr int kWatchPollsPerAsk = 50;  ///< the ground station's HEARTBEAT and the rates: each second

void ask_for_rates(ml::Link& link, ml::Encoder& encoder, uint8_t vehicle, bool truth) {
  send_gcs_heartbeat(link, encoder);
  // 20 Hz of the vehicle's time; GLOBAL_POSITION_INT is the frame PX4 orbits in.
  for (uint32_t id : {ml::msg::LOCAL_POSITION_NED, ml::msg::GLOBAL_POSITION_INT, ml::msg::ATTITUDE})
    send_command(link, encoder, vehicle, ml::cmd::SET_MESSAGE_INTERVAL, static_cast<float>(id), 50000);
  // PX4 SIH's ground truth at the same rate: where the vehicle really flew, beside its estimate.
  if (truth)
    send_command(link, encoder, vehicle, ml::cmd::SET_MESSAGE_INTERVAL, static_cast<float>(ml::msg::HIL_STATE_QUATERNION),
                 50000);
  // The mode at 10 Hz, as eamos asks for it (ArduPilot takes it; PX4 does not).
  send_command(link, encoder, vehicle, ml::cmd::SET_MESSAGE_INTERVAL, static_cast<float>(ml::msg::HEARTBEAT), 100000);
}

// The heading of a w, x, y, z quaternion (body to north-east-down), rad from north.
double yaw_of(const std::array<float, 4>& q) {
  return std::atan2(2.0 * (q[0] * q[3] + q[1] * q[2]), 1.0 - 2.0 * (q[2] * q[2] + q[3] * q[3]));
}

void request_heartbeat(ml::Link& link, ml::Encoder& encoder, uint8_t vehicle) {
  send_command(link, encoder, vehicle, ml::cmd::REQUEST_MESSAGE, static_cast<float>(ml::msg::HEARTBEAT));
}
}  // namespace

struct SitlWatch::State {
  std::mutex mutex;
  std::vector<VehicleSample> samples;
  uint32_t custom_mode = 0;
  bool armed = false;
  int32_t lat_e7 = 0, lon_e7 = 0, orbit_lat_e7 = 0, orbit_lon_e7 = 0, true_lat_e7 = 0, true_lon_e7 = 0;
  double yaw = 0, true_yaw = 0;
  std::unique_ptr<ml::Link> link;
  std::thread asker;
  std::mutex stop_mutex;
  std::condition_variable stop_cv;
  bool stop = false;
};

SitlWatch::SitlWatch(const SitlFleet& fleet, int i) : state_(std::make_unique<State>()) {
  const uint8_t vehicle = static_cast<uint8_t>(fleet.sysid(i));
  const int n = fleet.sysid(i) - 1;
  std::string url = fleet.autopilot() == Autopilot::ardupilot ? "tcp://127.0.0.1:" + std::to_string(5762 + 10 * n)
                                                              : "udpout://127.0.0.1:" + std::to_string(18570 + n);
  State* st = state_.get();
  auto opened = ml::Link::open(*eamos::fleet::parse_link_url(url).endpoint, [st, vehicle](ml::Frame f) {
    if (f.sysid != vehicle || f.compid != 1) return;
    std::lock_guard lock(st->mutex);
    if (auto hb = ml::unpack_heartbeat(f.message)) {
      st->custom_mode = hb->custom_mode;
      st->armed = (hb->base_mode & 128u) != 0;
    }
    if (auto g = ml::unpack_global_position_int(f.message)) st->lat_e7 = g->lat, st->lon_e7 = g->lon;
    if (auto o = ml::unpack_orbit_execution_status(f.message)) st->orbit_lat_e7 = o->x, st->orbit_lon_e7 = o->y;
    if (auto t = ml::unpack_hil_state_quaternion(f.message)) {
      st->true_lat_e7 = t->lat, st->true_lon_e7 = t->lon;
      st->true_yaw = yaw_of(t->attitude_quaternion);
    }
    if (auto a = ml::unpack_attitude(f.message)) st->yaw = a->yaw;
    if (auto p = ml::unpack_local_position_ned(f.message))
      st->samples.push_back({now_s(), p->x, p->y, p->z, std::hypot(p->vx, p->vy), st->custom_mode, st->armed,
                             st->lat_e7, st->lon_e7, st->orbit_lat_e7, st->orbit_lon_e7, st->true_lat_e7,
                             st->true_lon_e7, st->yaw, st->true_yaw});
  });
  if (!opened.link) {
    error_ = "cannot watch SITL instance " + std::to_string(i) + " on " + url + ": " + opened.error;
    return;
  }
  st->link = std::move(opened.link);
  // A ground station's HEARTBEAT (PX4 sends its GCS link to whoever spoke to it) and the rates
  // of LOCAL_POSITION_NED, GLOBAL_POSITION_INT and HEARTBEAT, every second until the watch ends.
  const bool poll_heartbeat = fleet.autopilot() == Autopilot::px4;
  st->asker = std::thread([st, vehicle, poll_heartbeat] {
    ml::Encoder encoder{251, 190, 0};
    std::unique_lock lock(st->stop_mutex);
    for (int round = 0; !st->stop; ++round) {
      if (round % kWatchPollsPerAsk == 0) ask_for_rates(*st->link, encoder, vehicle, poll_heartbeat);
      // PX4 keeps its HEARTBEAT at 1 Hz (it answers the rate with MAV_RESULT_FAILED), so the
      // mode is asked for each round: at 1 Hz, samples up to a vehicle second after it left its
      // Orbit mode (braking off the circle) counted as orbit.
      if (poll_heartbeat) request_heartbeat(*st->link, encoder, vehicle);
      st->stop_cv.wait_for(lock, kWatchPoll, [st] { return st->stop; });
    }
  });
}

SitlWatch::~SitlWatch() {
  if (state_->asker.joinable()) {
    {
      std::lock_guard lock(state_->stop_mutex);
      state_->stop = true;
    }
    state_->stop_cv.notify_all();
    state_->asker.join();
  }
  state_->link.reset();
}

std::vector<VehicleSample> SitlWatch::samples() const {
  std::lock_guard lock(state_->mutex);
  return state_->samples;
}

}  // namespace eamos_test
