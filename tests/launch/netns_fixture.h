#pragma once
// The network namespace fixture of the bad-network tests (netns_test.cpp) and the attack
// tests (netns_attack_test.cpp): the namespaces, the relay, the processes. See netns_test.cpp.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/run_eamos.h"

extern char** environ;

namespace netns_support {

namespace fs = std::filesystem;

inline const std::vector<std::string> kDrones = {"A", "B", "C"};

/// A child process with its output on a pipe (and, optionally, its input on one).
struct Child {
  pid_t pid = -1;
  FILE* out = nullptr;
  FILE* in = nullptr;
  std::string seen;
};

/// Starts `argv` (found on PATH); its stdout and stderr go to a pipe, or to `log` when set.
inline Child start(const std::vector<std::string>& args, const std::string& log = "", bool with_input = false) {
  Child c;
  int out[2], in[2] = {-1, -1};
  if (pipe(out) != 0 || (with_input && pipe(in) != 0)) return c;
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  if (log.empty()) {
    posix_spawn_file_actions_adddup2(&fa, out[1], STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&fa, out[1], STDERR_FILENO);
  } else {
    posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  }
  if (with_input) {
    posix_spawn_file_actions_adddup2(&fa, in[0], STDIN_FILENO);
    posix_spawn_file_actions_addclose(&fa, in[1]);
  }
  posix_spawn_file_actions_addclose(&fa, out[0]);
  std::vector<std::string> all = args;
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  if (posix_spawnp(&c.pid, argv[0], &fa, nullptr, argv.data(), environ) != 0) c.pid = -1;
  posix_spawn_file_actions_destroy(&fa);
  close(out[1]);
  c.out = fdopen(out[0], "r");
  if (with_input) {
    close(in[0]);
    c.in = fdopen(in[1], "w");
  }
  return c;
}

/// Reads lines (each to `on_line`) until one holds `text` (true) or the output ends.
inline bool read_until(Child& c, const std::string& text, const std::function<void(const std::string&)>& on_line = {}) {
  char buf[4096];
  while (c.out && fgets(buf, sizeof buf, c.out)) {
    c.seen += buf;
    if (on_line) on_line(buf);
    if (!text.empty() && std::string(buf).find(text) != std::string::npos) return true;
  }
  return false;
}

inline int wait_exit(Child& c) {
  read_until(c, "");
  if (c.out) fclose(c.out);
  c.out = nullptr;
  if (c.in) fclose(c.in);
  c.in = nullptr;
  int raw = 0;
  if (c.pid <= 0 || waitpid(c.pid, &raw, 0) != c.pid) return -1;
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
}

inline int sh(const std::string& cmd) {
  int raw = std::system((cmd + " >/dev/null 2>&1").c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

inline std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline std::vector<nlohmann::json> read_trace(const fs::path& p) {
  std::vector<nlohmann::json> events;
  std::ifstream in(p);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) events.push_back(nlohmann::json::parse(line));
  return events;
}

/// Per drone, "event name outcome" of its actions and conditions in order (telemetry,
/// messages, graph nodes and the header are not the mission's story).
inline std::map<std::string, std::vector<std::string>> per_drone(const fs::path& trace) {
  std::map<std::string, std::vector<std::string>> order;
  for (const nlohmann::json& e : read_trace(trace)) {
    std::string event = e.value("event", "");
    if (event != "start" && event != "end" && event != "condition") continue;
    order[e["drone"]].push_back(e["event"].get<std::string>() + " " + e.value("name", "") + " " +
                                e.value("outcome", ""));
  }
  return order;
}

/// The namespaces, veths and addresses of one test: namespace k (0: the ground, then one
/// per drone) is 10.<net>.<k+1>.2, its relay side 10.<net>.<k+1>.1.
class Netns : public ::testing::Test {
 protected:
  void SetUp() override {
    if (geteuid() != 0) GTEST_SKIP() << "network namespace tests need root (CI runs them as root)";
    if (sh("ip netns list") != 0) GTEST_SKIP() << "no `ip netns` (iproute2) here";
    prefix_ = "enf" + std::to_string(getpid() % 100000);
    net_ = 100 + getpid() % 100;
    dir_ = fs::temp_directory_path() / (prefix_ + "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    for (int k = 0; k < namespaces(); ++k) {
      std::string ns = ns_name(k), r = prefix_ + std::to_string(k) + "r", n = prefix_ + std::to_string(k) + "n";
      std::string near = address(k, 1), far = address(k, 2);
      bool ok = sh("ip netns add " + ns) == 0 && sh("ip link add " + r + " type veth peer name " + n) == 0 &&
                sh("ip link set " + n + " netns " + ns) == 0 && sh("ip addr add " + near + "/24 dev " + r) == 0 &&
                sh("ip link set " + r + " up") == 0 && sh("ip -n " + ns + " addr add " + far + "/24 dev " + n) == 0 &&
                sh("ip -n " + ns + " link set " + n + " up") == 0 && sh("ip -n " + ns + " link set lo up") == 0 &&
                sh("ip -n " + ns + " route add default via " + near) == 0;
      made_.push_back(k);
      if (!ok) GTEST_SKIP() << "cannot create network namespace " << ns << " with a veth (ip netns add / ip link add)";
      write_config(k);
    }
    Output c = eamos_test::run_eamos("compile -q " + std::string(EAMOS_SOURCE_DIR) +
                                     "/tests/launch/missions/" + mission_ + " -o " + (dir_ / "deploy").string());
    ASSERT_EQ(c.status, 0) << c.out;
  }
  void TearDown() override {
    for (int k : made_) {
      sh("ip link del " + prefix_ + std::to_string(k) + "r");
      sh("ip netns del " + ns_name(k));
    }
    if (!HasFailure() && !dir_.empty()) fs::remove_all(dir_);
  }
  using Output = eamos_test::Output;

  /// The ground's, one per drone, and with `attacker_` one more: the attacker's, last.
  int namespaces() const { return static_cast<int>(kDrones.size()) + (attacker_ ? 2 : 1); }
  int attacker_namespace() const { return static_cast<int>(kDrones.size()) + 1; }
  std::string link_name(int k) const {
    return k == 0 ? "Ground" : k == attacker_namespace() ? "Attacker" : kDrones[k - 1];
  }
  std::string ns_name(int k) const { return prefix_ + "-" + std::to_string(k); }
  std::string address(int k, int end) const {
    return "10." + std::to_string(net_) + "." + std::to_string(k + 1) + "." + std::to_string(end);
  }
  fs::path config(int k) const { return dir_ / ("cyclone-" + std::to_string(k) + ".xml"); }
  /// Discovery and data port of participant index `k` on the test's domain (the RTPS
  /// port mapping: 7400 + 250 domain + 10 + 2k, and one more).
  int port(int k, int which) const { return 7400 + 250 * domain_ + 10 + 2 * k + which; }

  // SPDPInterval 1 s: a lost discovery datagram is sent again a second later, not 30.
  void write_config(int k) {
    std::ofstream out(config(k));
    out << "<CycloneDDS xmlns=\"https://cdds.io/config\"><Domain Id=\"any\"><General><Interfaces>"
        << "<NetworkInterface address=\"" << address(k, 2) << "\"/></Interfaces>"
        << "<AllowMulticast>false</AllowMulticast>"
        << "<ExternalNetworkAddress>" << address(k, 1) << "</ExternalNetworkAddress></General>"
        << "<Discovery><ParticipantIndex>" << k << "</ParticipantIndex>"
        << "<MaxAutoParticipantIndex>9</MaxAutoParticipantIndex><SPDPInterval>1s</SPDPInterval>"
        << "<Peers><Peer address=\"" << address(k, 1) << "\"/></Peers></Discovery></Domain></CycloneDDS>\n";
  }

  /// Starts the relay with `faults` ("--loss 0.1", ...); waits until it is ready.
  void start_relay(const std::vector<std::string>& faults) {
    std::vector<std::string> args = {EAMOS_RELAY, "--listen", "0.0.0.0"};
    for (int k = 0; k < namespaces(); ++k) {
      for (int which : {0, 1}) args.insert(args.end(), {"--route", std::to_string(port(k, which)) + "=" + address(k, 2)});
      args.insert(args.end(), {"--link", link_name(k) + "=" + address(k, 2)});
    }
    args.insert(args.end(), faults.begin(), faults.end());
    relay_ = start(args, "", true);
    ASSERT_TRUE(read_until(relay_, "ready")) << relay_.seen;
  }
  void relay_command(const std::string& command) {
    fprintf(relay_.in, "%s\n", command.c_str());
    fflush(relay_.in);
  }
  /// Ends the relay; returns its per-link figures.
  std::string stop_relay() {
    if (relay_.in) fclose(relay_.in);
    relay_.in = nullptr;
    wait_exit(relay_);
    return relay_.seen;
  }

  /// Flies hops.eamos: a DEX per drone in its namespace, the ground in namespace 0, all
  /// through the relay. `on_line` sees the ground's output.
  int fly(const std::string& extra, const std::function<void(const std::string&)>& on_line) {
    std::string common = " --domain " + std::to_string(domain_) + " --speed " + speed_ + " --liveliness-timeout " + lease_;
    for (std::size_t d = 0; d < kDrones.size(); ++d) {
      std::vector<std::string> args = {"ip", "netns", "exec", ns_name(static_cast<int>(d) + 1), EAMOS_BINARY, "dex",
                                       (dir_ / "deploy" / kDrones[d]).string(), "--dds-config",
                                       config(static_cast<int>(d) + 1).string(), "--start-timeout",
                                       std::to_string(std::stoi(barrier_timeout_) + 5),
                                       "--trace", (dir_ / (kDrones[d] + ".jsonl")).string()};
      std::istringstream more(common + dex_extra_);
      for (std::string a; more >> a;) args.push_back(a);
      dexes_.push_back(start(args, (dir_ / (kDrones[d] + ".log")).string()));
    }
    std::vector<std::string> args = {"ip", "netns", "exec", ns_name(0), EAMOS_BINARY, "launch",
                                     (dir_ / "deploy").string(), "--remote-only", "--dds-config", config(0).string(),
                                     "--trace", (dir_ / "trace.jsonl").string(), "--summary",
                                     (dir_ / "summary.json").string(), "--barrier-timeout", barrier_timeout_};
    std::istringstream more(common + " " + extra);
    for (std::string a; more >> a;) args.push_back(a);
    ground_ = start(args);
    read_until(ground_, "", on_line);
    int status = wait_exit(ground_);
    for (Child& c : dexes_) dex_status_.push_back(wait_exit(c));
    return status;
  }

  /// The in-process run's per-drone order, the reference.
  std::map<std::string, std::vector<std::string>> in_process_order() {
    Output r = eamos_test::run_eamos("run -q " + std::string(EAMOS_SOURCE_DIR) +
                                     "/tests/launch/missions/" + mission_ + " --trace " + (dir_ / "local.jsonl").string());
    EXPECT_EQ(r.status, 0) << r.out;
    return per_drone(dir_ / "local.jsonl");
  }

  std::string logs() {
    std::string all = "ground:\n" + ground_.seen + "relay:\n" + relay_.seen;
    for (const std::string& d : kDrones) all += d + ":\n" + read_text(dir_ / (d + ".log"));
    return all;
  }

  /// Each drone's failsafe time in its own trace (-1: none).
  std::map<std::string, double> failsafes() {
    std::map<std::string, double> at;
    for (const std::string& d : kDrones) {
      at[d] = -1;
      for (const nlohmann::json& e : read_trace(dir_ / (d + ".jsonl")))
        if (e["event"] == "failsafe") at[d] = e["t"];
    }
    return at;
  }

  /// Flies with `faults` on every datagram. With `must_complete`, expects completion in
  /// the in-process per-drone order; otherwise that, or a safe refusal: the barrier did
  /// not pass (a DDS Security handshake timed out under the loss; nobody moved) or every
  /// drone is in its failsafe. Never a hang, never a completion in another order.
  void expect_completes_in_order(const std::vector<std::string>& faults, bool must_complete) {
    auto reference = in_process_order();
    ASSERT_NO_FATAL_FAILURE(start_relay(faults));
    int status = fly("", {});
    std::string figures = stop_relay();
    std::cout << figures;  // the measured figures (docs/faults.md)
    EXPECT_NE(figures.find("link B: forwarded"), std::string::npos) << figures;  // it went through the relay
    if (status != 0 && !must_complete && ground_.seen.find("start barrier timed out") != std::string::npos) {
      std::cout << "outcome: refused at the start barrier\n";
      for (const std::string& d : kDrones) EXPECT_EQ(read_text(dir_ / (d + ".log")).find(d + ".Arm()"), std::string::npos) << logs();
      return;
    }
    if (status != 0 && !must_complete) {
      std::cout << "outcome: failed, every drone in its failsafe\n";
      nlohmann::json summary = nlohmann::json::parse(read_text(dir_ / "summary.json"));
      for (const std::string& d : kDrones) {
        const nlohmann::json& s = summary["drones"][d];
        bool safe = s.value("state", "") == "unknown" || (s["landed"] == true && s["armed"] == false);
        EXPECT_TRUE(safe) << d << "\n" << summary.dump(2) << logs();
      }
      return;
    }
    ASSERT_EQ(status, 0) << logs();
    std::cout << "outcome: completed\n";
    EXPECT_EQ(per_drone(dir_ / "trace.jsonl"), reference) << logs();
    for (int s : dex_status_) EXPECT_EQ(s, 0) << logs();
  }

  /// Cuts drone B's link once B is airborne (for `seconds`, or for good with 0); expects
  /// every drone in its failsafe within the lease of the cut.
  void expect_failsafe_within_lease_after_cut(double seconds) {
    ASSERT_NO_FATAL_FAILURE(start_relay({}));
    double cut_at = -1;
    int status = fly("--final-state-timeout 3", [&](const std::string& line) {
      if (cut_at < 0 && line.find("B.Takeoff(5)  succeeded") != std::string::npos) {
        char command[64];
        std::snprintf(command, sizeof command, seconds > 0 ? "cut B %g" : "cut B", seconds);
        relay_command(command);
        cut_at = std::stod(line);
      }
    });
    std::string figures = stop_relay();
    std::cout << figures;
    ASSERT_GT(cut_at, 0) << logs();
    EXPECT_EQ(status, 1) << logs();
    double within = (std::stod(lease_) + 1.0) * std::stod(speed_);  // the lease, plus a wall second to notice
    for (const auto& [drone, t] : failsafes()) {
      ASSERT_GE(t, 0) << drone << " has no failsafe\n" << logs();
      EXPECT_LE(t - cut_at, within) << drone << "\n" << logs();
      std::cout << drone << ": failsafe " << t - cut_at << " mission s after the cut\n";
    }
    nlohmann::json summary = nlohmann::json::parse(read_text(dir_ / "summary.json"));
    EXPECT_EQ(summary["status"], "failed");
    for (std::string d : {"A", "C"}) EXPECT_TRUE(summary["drones"][d]["landed"]) << d << summary.dump(2);
    if (seconds > 0)  // B came back and reported how it ended
      EXPECT_TRUE(summary["drones"]["B"]["landed"]) << summary.dump(2) << logs();
    else
      EXPECT_EQ(summary["drones"]["B"]["state"], "unknown") << summary.dump(2);
  }

  std::string mission_ = "hops.eamos";  ///< in tests/launch/missions; set before SetUp
  bool attacker_ = false;               ///< a namespace (and relay routes) for an attacker
  std::string dex_extra_;               ///< more options for every DEX (" --insecure")
  std::string barrier_timeout_ = "20";  ///< the ground's --barrier-timeout, wall s
  std::string prefix_;
  int net_ = 0;
  int domain_ = 170;
  std::string speed_ = "5", lease_ = "1";
  fs::path dir_;
  std::vector<int> made_;
  Child relay_, ground_;
  std::vector<Child> dexes_;
  std::vector<int> dex_status_;
};

}  // namespace netns_support
