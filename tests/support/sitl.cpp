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
#include <mutex>
#include <sstream>

#include "mavlink/enums.h"
#include "mavlink/link.h"
#include "mavlink/messages.h"
#include "mavlink/payloads.h"

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

}  // namespace

// Short-lived links of the test's own, one per instance and all open at once (a STATUSTEXT
// is sent once, to whoever is connected then); closed before eamos opens the same ports.
bool SitlFleet::wait_ready(double timeout_s, std::string& error) {
  double deadline = now_s() + timeout_s;
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

}  // namespace eamos_test
