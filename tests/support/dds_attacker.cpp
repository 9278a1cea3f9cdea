// eamos-dds-attacker: a process on a mission's DDS domain that is not one of its drones,
// for the attack tests of tests/launch/netns_attack_test.cpp. It uses
// the project's own transport (DdsNode, the mission's IDL and partitions), so what it
// writes is exactly what a DEX would write: only who writes it is wrong.
//
//   eamos-dds-attacker --domain N --hash MISSION_HASH --drones N [--dds-config FILE]
//                      [--security DIR --as DRONE]
//
// Without --security it opens one participant per drone index, each writing in that
// drone's partition (what a process without credentials can try); with --security DIR
// (another mission's or another compilation's credentials) one participant, posing as
// drone --as (and claiming to be whoever a command names). Commands on standard input, one a line, each answered "ok LINE" (or
// "error LINE: why") on standard output once written:
//   finished RUN FROM            FINISHED from drone FROM at mission time 1
//   abort RUN FROM SENDER [FAILED]   ABORT written by FROM's participant, its `drone`
//                                field SENDER (out of range to probe the checks), naming
//                                FAILED (a drone name) as the failed drone when given
//   trigger RUN FROM TO NODE SEQ a trigger "node NODE of FROM ended" to drone TO
//   replay                       from now on, writes every trigger it reads a second time
//   telemetry RUN FROM X COUNT   COUNT telemetry samples of FROM at x = X, z = 5, 2 ms apart
//   status RUN FROM [NONCE]      one status of FROM (running, busy) with NONCE (0 or
//                                absent: FROM's nonce from the newest START it read), then
//                                silence: its liveliness is never asserted again
// "ready" is printed once the participants exist; at EOF it prints what it read
// ("read: N triggers, N starts") and exits 0.
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "transport/dds_node.h"

namespace {

using namespace eamos::transport;

struct Args {
  int domain = 0;
  std::string hash;
  int drones = 0;
  std::string config;
  std::string security;
  int as = 0;
};

bool parse(int argc, char** argv, Args& a) {
  for (int i = 1; i + 1 < argc; i += 2) {
    std::string k = argv[i], v = argv[i + 1];
    if (k == "--domain") a.domain = std::atoi(v.c_str());
    else if (k == "--hash") a.hash = v;
    else if (k == "--drones") a.drones = std::atoi(v.c_str());
    else if (k == "--dds-config") a.config = v;
    else if (k == "--security") a.security = v;
    else if (k == "--as") a.as = std::atoi(v.c_str());
    else return false;
  }
  return !a.hash.empty() && a.drones > 0;
}

class Attacker {
 public:
  explicit Attacker(Args a) : a_(std::move(a)) {}
  ~Attacker() {
    // The first node made the domain and ends it for all: the others go first.
    while (!nodes_.empty()) nodes_.pop_back();
  }

  bool open(std::string& error) {
    if (!a_.security.empty()) return open_as(a_.as, error);
    for (int d = 0; d < a_.drones; ++d)
      if (!open_as(d, error)) return false;
    return true;
  }

  /// One command line; "" when done, otherwise why not.
  std::string run(const std::string& line) {
    std::istringstream in(line);
    std::string verb;
    in >> verb;
    if (verb == "replay") {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!replay_) std::thread([this] { replay_loop(); }).detach();  // ends with the process
      replay_ = true;
      return "";
    }
    std::uint64_t run = 0;
    int from = 0;
    if (!(in >> run >> from)) return "expected RUN FROM";
    DdsNode* node = as(from);
    if (!node) return "not posing as drone " + std::to_string(from);
    if (verb == "finished") return finished(*node, run, from);
    if (verb == "abort") return abort(*node, run, in);
    if (verb == "trigger") return trigger(*node, run, from, in);
    if (verb == "telemetry") return telemetry(*node, run, from, in);
    if (verb == "status") return status(*node, run, from, in);
    return "unknown command";
  }

  std::string summary() {
    std::lock_guard<std::mutex> lock(mutex_);
    return "read: " + std::to_string(triggers_read_) + " triggers, " + std::to_string(starts_read_) +
           " starts, replayed " + std::to_string(replayed_);
  }

 private:
  bool open_as(int who, std::string& error) {
    DdsOptions o;
    o.domain = a_.domain;
    o.config_file = a_.config;
    o.mission_hash = a_.hash;
    o.self = who;
    o.security_folder = a_.security;
    DdsHandlers h;
    h.limits.drones = a_.drones;
    h.dropped = [](const std::string&) {};
    h.trigger = [this](TriggerSample s) { on_trigger(std::move(s)); };
    h.lifecycle = [this](LifecycleSample s) { on_lifecycle(std::move(s)); };
    std::unique_ptr<DdsNode> node = DdsNode::open(o, std::move(h), error);
    if (!node) return false;
    nodes_.push_back(std::move(node));
    posing_.push_back(who);
    return true;
  }

  // With credentials there is one participant: it claims to be anyone, in its partition.
  DdsNode* as(int who) {
    if (!a_.security.empty()) return nodes_.empty() ? nullptr : nodes_[0].get();
    for (std::size_t i = 0; i < posing_.size(); ++i)
      if (posing_[i] == who) return nodes_[i].get();
    return nullptr;
  }

  // Every participant reads every trigger: count and replay each (sender, seq, receiver)
  // once, from the participant of its sender (the replays come back here too: seen). The
  // write is the replay thread's: a write from a listener, delivered to this process's
  // own readers, can wait for their listeners forever in Cyclone 0.10.2.
  void on_trigger(TriggerSample s) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!seen_.insert({s.message.from, s.seq, s.to}).second) return;
    ++triggers_read_;
    if (!replay_) return;
    ++replayed_;
    to_replay_.push_back(std::move(s));
    replay_cv_.notify_one();
  }

  void replay_loop() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      replay_cv_.wait(lock, [this] { return !to_replay_.empty(); });
      TriggerSample s = std::move(to_replay_.front());
      to_replay_.pop_front();
      lock.unlock();
      if (DdsNode* node = as(s.message.from)) node->write(s);
      lock.lock();
    }
  }

  void on_lifecycle(LifecycleSample s) {
    if (s.kind != LifecycleKind::start) return;
    std::lock_guard<std::mutex> lock(mutex_);
    ++starts_read_;
    start_nonces_ = s.nonces;
  }

  std::string finished(DdsNode& node, std::uint64_t run, int from) {
    LifecycleSample s{a_.hash, from, LifecycleKind::finished, run};
    s.t = 1.0;
    return node.write(s) ? "" : "write refused";
  }

  std::string abort(DdsNode& node, std::uint64_t run, std::istringstream& in) {
    int sender = 0;
    if (!(in >> sender)) return "expected SENDER";
    LifecycleSample s{a_.hash, sender, LifecycleKind::abort, run};
    s.reason = "forged by the attacker";
    s.t = 1.0;
    std::string failed;
    if (in >> failed) s.failure = eamos::dex::Failure{failed, "Takeoff", 3, "forged by the attacker"};
    return node.write(s) ? "" : "write refused";
  }

  std::string trigger(DdsNode& node, std::uint64_t run, int from, std::istringstream& in) {
    int to = 0, meg = 0;
    std::uint64_t seq = 0;
    if (!(in >> to >> meg >> seq)) return "expected TO NODE SEQ";
    eamos::dex::Message m;
    m.mission_hash = a_.hash;
    m.from = from;
    m.meg = meg;
    {
      // Its own participants read it too: not a trigger of the mission's, not one to replay.
      std::lock_guard<std::mutex> lock(mutex_);
      seen_.insert({from, seq, to});
    }
    return node.write(TriggerSample{run, to, seq, m}) ? "" : "write refused";
  }

  // The attacker's own pace (2 ms: 25 forged samples to each real one at 20 Hz), not a test waiting.
  std::string telemetry(DdsNode& node, std::uint64_t run, int from, std::istringstream& in) {
    double x = 0;
    int count = 0;
    if (!(in >> x >> count)) return "expected X COUNT";
    for (int i = 0; i < count; ++i) {
      TelemetrySample s;
      s.run_id = run;
      s.telemetry.mission_hash = a_.hash;
      s.telemetry.from = from;
      s.telemetry.state.x = x;
      s.telemetry.state.z = 5;
      s.telemetry.state.armed = true;
      s.telemetry.state.landed = false;
      s.telemetry.state.battery = 90;
      if (!node.write(s)) return "write refused";
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return "";
  }

  std::string status(DdsNode& node, std::uint64_t run, int from, std::istringstream& in) {
    std::uint64_t nonce = 0;
    in >> nonce;
    if (nonce == 0) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (from < static_cast<int>(start_nonces_.size())) nonce = start_nonces_[from];
    }
    StatusSample s;
    s.mission_hash = a_.hash;
    s.drone = from;
    s.run_id = run;
    s.nonce = nonce == 0 ? 1 : nonce;
    s.phase = Phase::running;
    s.busy = true;
    node.assert_alive();  // once: then silence, and its liveliness lapses
    return node.write(s) ? "" : "write refused";
  }

  Args a_;
  std::vector<std::unique_ptr<DdsNode>> nodes_;
  std::vector<int> posing_;
  std::mutex mutex_;
  bool replay_ = false;
  std::condition_variable replay_cv_;
  std::deque<TriggerSample> to_replay_;
  std::set<std::tuple<int, std::uint64_t, int>> seen_;
  std::uint64_t triggers_read_ = 0, starts_read_ = 0, replayed_ = 0;
  std::vector<std::uint64_t> start_nonces_;
};

}  // namespace

int main(int argc, char** argv) {
  Args a;
  if (!parse(argc, argv, a)) {
    std::cerr << "usage: eamos-dds-attacker --domain N --hash MISSION_HASH --drones N [--dds-config FILE] "
                 "[--security DIR --as DRONE]\n";
    return 2;
  }
  Attacker attacker(a);
  std::string error;
  if (!attacker.open(error)) {
    std::cout << "error: " << error << std::endl;
    return 1;
  }
  std::cout << "ready" << std::endl;
  for (std::string line; std::getline(std::cin, line);) {
    if (line.empty()) continue;
    std::string why = attacker.run(line);
    std::cout << (why.empty() ? "ok " + line : "error " + line + ": " + why) << std::endl;
  }
  std::cout << attacker.summary() << std::endl;
  // Not through the destructors: the replay thread may be writing, and deleting a
  // participant whose reader a write is delivering to (in this process) can wait for it
  // forever in Cyclone 0.10.2. The operating system closes the sockets.
  std::_Exit(0);
}
