#include "support/sitl.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <mutex>
#include <sstream>
#include <thread>

#include "mavlink/enums.h"
#include "mavlink/link.h"
#include "mavlink/messages.h"
#include "mavlink/payloads.h"
#include "mavlink/url.h"

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

void geographic_home(const SitlHome& h, double& lat, double& lon) {
  double per_lat, per_lon;
  metres_per_degree(kOriginLat, per_lat, per_lon);
  lat = kOriginLat + h.y / per_lat;
  lon = kOriginLon + h.x / per_lon;
}

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
  for (int i = 0; i < static_cast<int>(options_.homes.size()); ++i)
    if (!start_one(i, error)) return false;
  return true;
}

std::vector<std::string> SitlFleet::command_line(int i, const std::string& bin) const {
  double lat, lon;
  geographic_home(options_.homes[i], lat, lon);
  if (options_.autopilot == Autopilot::ardupilot) {
    std::string parm = (fs::path(bin).parent_path() / "copter.parm").string();
    return {bin, "-I", std::to_string(instance_number(i)), "--model", "+", "--speedup", fixed(options_.speedup, 2),
            "--sysid", std::to_string(sysid(i)),
            "--home", fixed(lat, 8) + "," + fixed(lon, 8) + "," + fixed(kOriginAlt, 1) + ",0",
            "--defaults", parm, "-w", "--serial0", "tcp:0"};
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
  std::vector<std::string> args = command_line(i, bin);
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
    int out = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
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
  instances_.back().pid = pid;
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
  for (auto& inst : instances_)
    if (inst.pid > 0) kill(inst.pid, SIGTERM);
  double deadline = now_s() + 5.0;
  for (auto& inst : instances_) {
    if (inst.pid <= 0) continue;
    // Reap with a bounded grace period, then force: a test must never leave one behind.
    while (waitpid(inst.pid, nullptr, WNOHANG) == 0) {
      if (now_s() > deadline) {
        kill(inst.pid, SIGKILL);
        waitpid(inst.pid, nullptr, 0);
        break;
      }
      usleep(20000);
    }
    inst.pid = -1;
  }
  for (auto& inst : instances_) {
    std::error_code ec;
    if (!std::getenv("EAMOS_KEEP_SITL_DIRS")) fs::remove_all(inst.dir, ec);
  }
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
  bool ready() const { return heartbeat && prearm_ok && position && (ekf_uses_gps || !need_ekf_text); }
  std::string missing() const {
    if (!heartbeat) return "no HEARTBEAT";
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
  if (auto t = ml::unpack_statustext(f.message))
    if (t->text.find("is using GPS") != std::string::npos) r.ekf_uses_gps = true;
  r.changed.notify_all();
}

// Asks for the two messages readiness is judged by, at 2 Hz, announcing a ground station.
void ask_for_status(ml::Link& link, ml::Encoder& encoder, uint8_t sysid) {
  ml::Heartbeat hb;
  hb.type = 6;       // MAV_TYPE_GCS
  hb.autopilot = 8;  // MAV_AUTOPILOT_INVALID
  link.send(encoder.encode(ml::pack(hb)));
  for (uint32_t id : {ml::msg::SYS_STATUS, ml::msg::GLOBAL_POSITION_INT}) {
    ml::CommandLong c;
    c.target_system = sysid;
    c.target_component = 1;
    c.command = ml::cmd::SET_MESSAGE_INTERVAL;
    c.param[0] = static_cast<float>(id);
    c.param[1] = 500000;
    link.send(encoder.encode(ml::pack(c)));
  }
}

// What the camera set-up has seen of one ArduPilot instance, filled on the link's thread.
struct CameraSetup {
  std::mutex mutex;
  std::condition_variable changed;
  bool heartbeat = false;
  std::map<std::string, float> params;  ///< PARAM_VALUEs by name
};

ml::Message command_long(uint8_t sysid, uint16_t id, std::array<float, 7> params) {
  ml::CommandLong c;
  c.target_system = sysid;
  c.target_component = 1;
  c.command = id;
  c.param = params;
  return ml::pack(c);
}

// Waits (bounded by `deadline`, resending `ask` every half second) until `done` holds.
bool wait_for(CameraSetup& cs, double deadline, const std::function<void()>& ask, const std::function<bool()>& done) {
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

// ArduPilot creates its camera backend only at boot. CAM1_TYPE in a second --defaults file
// did not take on this 4.7 build (PARAM_VALUE said 0 after boot), so the camera is set up as
// a user does it: PARAM_SET CAM1_TYPE 1 (saved to the instance's eeprom.bin), then
// MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN; the instance restarts in place and keeps the parameter.
bool SitlFleet::set_up_ardupilot_camera(int i, double deadline, std::string& error) {
  CameraSetup cs;
  const uint8_t vehicle = static_cast<uint8_t>(sysid(i));
  ml::FrameHandler handler = [&cs, vehicle](ml::Frame f) {
    if (f.sysid != vehicle || f.compid != 1) return;
    std::lock_guard lock(cs.mutex);
    if (ml::unpack_heartbeat(f.message)) cs.heartbeat = true;
    if (auto p = ml::unpack_param_value(f.message)) cs.params[p->param_id] = p->param_value;
    cs.changed.notify_all();
  };
  auto open = [&]() -> std::unique_ptr<ml::Link> {
    ml::OpenResult opened;
    while (!opened.link && now_s() < deadline) {
      opened = ml::Link::open(*ml::parse_url(connection(i)).endpoint, handler, 0.2);
      if (!opened.link) usleep(100000);
    }
    return std::move(opened.link);
  };
  std::unique_ptr<ml::Link> link = open();
  ml::Encoder encoder{250, 190, 0};
  auto send = [&](const ml::Message& m) {
    if (link) link->send(encoder.encode(m));
  };
  auto ask = [&](const char* param) {
    ml::Heartbeat hb;
    hb.type = 6;
    hb.autopilot = 8;
    send(ml::pack(hb));
    send(ml::pack(ml::ParamRequestRead{vehicle, 1, param, -1}));
  };
  auto param = [&](const char* name) -> std::optional<float> {
    auto it = cs.params.find(name);
    return it == cs.params.end() ? std::nullopt : std::optional<float>(it->second);
  };
  // STAT_BOOTCNT counts the autopilot's boots: one more is the reboot done.
  const char* step = "reading STAT_BOOTCNT";
  bool ok = link && wait_for(cs, deadline, [&] { ask("STAT_BOOTCNT"); }, [&] { return param("STAT_BOOTCNT").has_value(); });
  std::unique_lock boots_lock(cs.mutex);
  float boots = ok ? *param("STAT_BOOTCNT") : 0;
  boots_lock.unlock();
  // ArduPilot saves a parameter from its IO thread, after the PARAM_VALUE echo: on a loaded
  // machine a reboot right after the echo sometimes came first and CAM1_TYPE was 0 again.
  // So: set, reboot, check; up to three times.
  for (int attempt = 0; ok && attempt < 3; ++attempt) {
    step = "PARAM_SET CAM1_TYPE 1";
    {
      std::lock_guard lock(cs.mutex);
      cs.params.erase("CAM1_TYPE");
    }
    ok = wait_for(cs, deadline, [&] { send(ml::pack(ml::ParamSet{vehicle, 1, "CAM1_TYPE", 1.0f, ml::param_type::INT8})); },
                  [&] { return param("CAM1_TYPE") == 1.0f; });
    if (!ok) break;
    step = "rebooting";
    // param1 = 1: reboot the autopilot. SITL restarts by exec in the same process; connect
    // again until the new boot answers, repeating the reboot while the old one still does.
    auto reboot = [&] { send(command_long(vehicle, 246, {1, 0, 0, 0, 0, 0, 0})); };
    reboot();
    auto rebooted = [&] { return param("STAT_BOOTCNT") > boots; };
    int tries = 0;
    while (ok) {
      link.reset();
      link = open();
      ok = link != nullptr;
      if (ok && wait_for(cs, std::min(deadline, now_s() + 2.0), [&] { ask("STAT_BOOTCNT"); }, rebooted)) break;
      std::unique_lock lock(cs.mutex);
      if (param("STAT_BOOTCNT") == boots && ++tries % 2 == 0) reboot();  // the old boot answers still
      lock.unlock();
      ok = now_s() < deadline;
    }
    if (!ok) break;
    {
      std::lock_guard lock(cs.mutex);
      boots = *param("STAT_BOOTCNT");
      cs.params.erase("CAM1_TYPE");
    }
    step = "checking CAM1_TYPE after the reboot";
    ok = wait_for(cs, deadline, [&] { ask("CAM1_TYPE"); }, [&] { return param("CAM1_TYPE").has_value(); });
    std::lock_guard lock(cs.mutex);
    if (ok && param("CAM1_TYPE") == 1.0f) break;
    ok = ok && attempt < 2;
  }
  link.reset();
  if (!ok)
    error = "SITL instance " + std::to_string(i) + ": camera set-up did not finish: " + step + "\n" + log_tail(i);
  return ok;
}

// One parameter set as a ground station sets it: PARAM_SET, resent until PARAM_VALUE echoes
// the value (a whole number for an integer parameter: ArduPilot rounds). For parameters
// ArduPilot reads while it runs (no reboot).
bool SitlFleet::set_ardupilot_param(int i, const char* name, float value, double deadline, std::string& error) {
  CameraSetup cs;  // the same bookkeeping: HEARTBEAT seen, PARAM_VALUEs by name
  const uint8_t vehicle = static_cast<uint8_t>(sysid(i));
  ml::FrameHandler handler = [&cs, vehicle](ml::Frame f) {
    if (f.sysid != vehicle || f.compid != 1) return;
    std::lock_guard lock(cs.mutex);
    if (auto p = ml::unpack_param_value(f.message)) cs.params[p->param_id] = p->param_value;
    cs.changed.notify_all();
  };
  ml::OpenResult opened;
  while (!opened.link && now_s() < deadline) {
    opened = ml::Link::open(*ml::parse_url(connection(i)).endpoint, handler, 0.2);
    if (!opened.link) usleep(100000);
  }
  ml::Encoder encoder{250, 190, 0};
  bool ok = opened.link && wait_for(cs, deadline,
                                    [&] {
                                      opened.link->send(encoder.encode(ml::pack(
                                          ml::ParamSet{vehicle, 1, name, value, ml::param_type::INT32})));
                                    },
                                    [&] {
                                      auto it = cs.params.find(name);
                                      return it != cs.params.end() && std::fabs(it->second - value) < 0.01f;
                                    });
  opened.link.reset();
  if (!ok) error = "SITL instance " + std::to_string(i) + ": " + name + " was not set\n" + log_tail(i);
  return ok;
}

// Short-lived links of the test's own, one per instance and all open at once (a STATUSTEXT
// is sent once, to whoever is connected then); closed before eamos opens the same ports.
bool SitlFleet::wait_ready(double timeout_s, std::string& error) {
  double deadline = now_s() + timeout_s;
  if (options_.camera && options_.autopilot == Autopilot::ardupilot)
    for (int i = 0; i < size(); ++i)
      if (!set_up_ardupilot_camera(i, deadline, error)) return false;
  // Remaining % is consumed mAh against BATT_CAPACITY: the capacity that lasts
  // battery_drain_s at the SITL copter's hover current.
  if (options_.battery_drain_s > 0 && options_.autopilot == Autopilot::ardupilot)
    for (int i = 0; i < size(); ++i)
      if (!set_ardupilot_param(i, "BATT_CAPACITY",
                               std::round(static_cast<float>(kArduCopterSitlHoverA * options_.battery_drain_s / 3.6)), deadline,
                               error))
        return false;
  std::vector<std::unique_ptr<Readiness>> state;
  std::vector<std::unique_ptr<ml::Link>> links;
  for (int i = 0; i < size(); ++i) {
    state.push_back(std::make_unique<Readiness>());
    state.back()->need_ekf_text = options_.autopilot == Autopilot::ardupilot;
    Readiness* r = state.back().get();
    uint8_t vehicle = static_cast<uint8_t>(sysid(i));
    // ArduPilot opens its TCP port a moment after it starts: try again until the deadline.
    ml::OpenResult opened;
    while (!opened.link && now_s() < deadline) {
      opened = ml::Link::open(*ml::parse_url(connection(i)).endpoint,
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
  for (int i = 0; i < size(); ++i) {
    Readiness& r = *state[i];
    std::unique_lock lock(r.mutex);
    while (!r.ready()) {
      if (now_s() > deadline) {
        error = "SITL instance " + std::to_string(i) + " not ready after " + fixed(timeout_s, 0) +
                " s: " + r.missing() + "\n" + log_tail(i);
        return false;
      }
      lock.unlock();
      for (int k = 0; k < size(); ++k) ask_for_status(*links[k], encoder, static_cast<uint8_t>(sysid(k)));
      lock.lock();
      r.changed.wait_for(lock, std::chrono::milliseconds(500), [&] { return r.ready(); });
    }
  }
  return true;
}

// --- a second ground station ---------------------------------------------------------------

struct SitlWatch::State {
  std::mutex mutex;
  std::vector<VehicleSample> samples;
  uint32_t custom_mode = 0;
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
  auto opened = ml::Link::open(*ml::parse_url(url).endpoint, [st, vehicle](ml::Frame f) {
    if (f.sysid != vehicle || f.compid != 1) return;
    std::lock_guard lock(st->mutex);
    if (auto hb = ml::unpack_heartbeat(f.message)) st->custom_mode = hb->custom_mode;
    if (auto p = ml::unpack_local_position_ned(f.message))
      st->samples.push_back({now_s(), p->x, p->y, p->z, std::hypot(p->vx, p->vy), st->custom_mode});
  });
  if (!opened.link) {
    error_ = "cannot watch SITL instance " + std::to_string(i) + " on " + url + ": " + opened.error;
    return;
  }
  st->link = std::move(opened.link);
  // A ground station's HEARTBEAT (PX4 sends its GCS link to whoever spoke to it) and the rate
  // of LOCAL_POSITION_NED, every second until the watch ends.
  st->asker = std::thread([st, vehicle] {
    ml::Encoder encoder{251, 190, 0};
    std::unique_lock lock(st->stop_mutex);
    while (!st->stop) {
      ml::Heartbeat hb;
      hb.type = 6;
      hb.autopilot = 8;
      st->link->send(encoder.encode(ml::pack(hb)));
      ml::CommandLong c;
      c.target_system = vehicle;
      c.target_component = 1;
      c.command = ml::cmd::SET_MESSAGE_INTERVAL;
      c.param[0] = static_cast<float>(ml::msg::LOCAL_POSITION_NED);
      c.param[1] = 50000;  // 20 Hz of the vehicle's time
      st->link->send(encoder.encode(ml::pack(c)));
      st->stop_cv.wait_for(lock, std::chrono::seconds(1), [st] { return st->stop; });
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
