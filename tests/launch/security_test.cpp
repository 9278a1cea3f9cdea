// No one else flies our drones (docs/security.md): real `eamos launch` runs of Listing 2
// over Cyclone DDS with DDS Security on, attacked from this test process by DDS
// participants of its own — without the mission's credentials, or with those of another
// compilation of the same mission — that forge ABORT, FINISHED and triggers with the
// mission hash and the run id (which the ground prints). The same attack on the same
// mission flown with --insecure is obeyed: that is what the secure runs are measured against.
// With --insecure the attacker can pose as any drone, and what still protects the mission
// is what every DEX checks in every sample: those tests fail without those checks.
// Each test has its own DDS domain (150-159); nothing sleeps: the tests act on output lines.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/run_eamos.h"
#include "transport/dds_node.h"

namespace {

namespace fs = std::filesystem;
using eamos_test::Output;
using namespace eamos::transport;

std::string source(const std::string& name) { return std::string(EAMOS_SOURCE_DIR) + "/examples/" + name; }

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs a shell command; its stdout and stderr.
std::string shell(const std::string& cmd) {
  std::string out;
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return out;
  char buf[4096];
  while (fgets(buf, sizeof buf, p)) out += buf;
  pclose(p);
  return out;
}

/// DDS participants of the test process that pose as drones of a mission: one per drone
/// index (with --insecure a writer's partition is whatever its participant says).
class Attacker {
 public:
  Attacker(int domain, std::string hash, int drones) : domain_(domain), hash_(std::move(hash)), drones_(drones) {}
  ~Attacker() {
    // The first node made the domain and ends it for all: the others go first.
    while (!nodes_.empty()) nodes_.pop_back();
  }
  /// Opens a participant posing as drone `who`, with the credentials in `security` ("": none).
  void pose_as(int who, const std::string& security = "", bool replay = false) {
    DdsOptions o;
    o.domain = domain_;
    o.mission_hash = hash_;
    o.self = who;
    o.security_folder = security;
    DdsHandlers h;
    h.limits.drones = drones_;
    h.dropped = [](const std::string&) {};
    if (replay) h.trigger = [this, who](TriggerSample s) { replay_trigger(who, s); };
    std::string error;
    nodes_.push_back(DdsNode::open(o, std::move(h), error));
    ASSERT_NE(nodes_.back(), nullptr) << error;
    posing_.push_back(who);
  }
  DdsNode& as(int who) {
    for (std::size_t i = 0; i < posing_.size(); ++i)
      if (posing_[i] == who) return *nodes_[i];
    throw std::runtime_error("not posing as that drone");
  }
  /// ABORT, FINISHED from every drone (at mission time 1) and a trigger of a node that
  /// does not exist: what the attacker sent.
  void forge_everything(std::uint64_t run) {
    forge_abort(run, 1, {});
    forge_finished(run);
    forge_junk_trigger(run);
  }
  void forge_abort(std::uint64_t run, int from, std::optional<eamos::dex::Failure> failure) {
    LifecycleSample abort{hash_, from, LifecycleKind::abort, run};
    abort.reason = "forged by the test";
    abort.t = 1.0;
    abort.failure = std::move(failure);
    as(from).write(abort);
  }
  void forge_finished(std::uint64_t run) {
    for (int d = 0; d < drones_; ++d) forge_finished_from(run, d);
  }
  void forge_finished_from(std::uint64_t run, int d) {
    LifecycleSample finished{hash_, d, LifecycleKind::finished, run};
    finished.t = 1.0;
    as(d).write(finished);
  }
  void forge_junk_trigger(std::uint64_t run) {
    eamos::dex::Message m;
    m.mission_hash = hash_;
    m.from = 0;
    m.meg = 99999;
    as(0).write(TriggerSample{run, 1, 1, m});
  }
  std::uint64_t replayed() {
    std::lock_guard<std::mutex> lock(mutex_);
    return replayed_;
  }

 private:
  /// Writes every trigger `who` sent a second time, same sequence number and all.
  void replay_trigger(int who, const TriggerSample& s) {
    if (s.message.from != who) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!seen_.insert({s.message.from, s.seq, s.to}).second) return;
      ++replayed_;
    }
    as(who).write(s);
  }

  int domain_;
  std::string hash_;
  int drones_;
  std::vector<std::unique_ptr<DdsNode>> nodes_;
  std::vector<int> posing_;
  std::mutex mutex_;
  std::set<std::tuple<int, std::uint64_t, int>> seen_;
  std::uint64_t replayed_ = 0;
};

class Security : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eamos-sec-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  /// Compiles Listing 2 into dir/name; returns its mission hash.
  std::string compile(const std::string& name, const std::string& extra = "") {
    Output c = eamos_test::run_eamos("compile -q " + source("listing2.eamos") + " -o " + (dir_ / name).string() + extra);
    EXPECT_EQ(c.status, 0) << c.out;
    std::ifstream in(dir_ / name / "manifest.json");
    return nlohmann::json::parse(in)["mission_hash"].get<std::string>();
  }
  /// Launches dir/deploy; `attack(run)` runs once, when Drone1's takeoff succeeded
  /// (`at_start`: as soon as the ground started the run).
  Output launch(int domain, const std::string& extra, const std::function<void(std::uint64_t)>& attack,
                bool at_start = false) {
    std::uint64_t run = 0;
    bool attacked = false;
    return eamos_test::run_eamos(
        "launch " + (dir_ / "deploy").string() + " --speed 5 --domain " + std::to_string(domain) + " --summary " +
            (dir_ / "summary.json").string() + extra,
        [&](const std::string& line) {
          const std::string key = "starting run ";
          auto at = line.find(key);
          if (at != std::string::npos) run = std::stoull(line.substr(at + key.size()));
          bool now = at_start ? run != 0 : line.find("Drone1.Takeoff(4)  succeeded") != std::string::npos;
          if (now && !attacked && run != 0) {
            attacked = true;
            attack(run);
          }
        });
  }
  /// Every DEX's log, for what they said they ignored.
  std::string dex_logs() {
    std::string logs;
    for (const char* d : {"Drone1", "Drone2", "Drone3"}) logs += read_text(dir_ / "deploy" / d / "dex.log");
    return logs;
  }
  /// The mission flew to its end: completed, every drone landed, for longer than the
  /// forged FINISHED's mission time.
  void expect_flown_to_the_end(const Output& r) {
    ASSERT_EQ(r.status, 0) << r.out << dex_logs();
    nlohmann::json summary = nlohmann::json::parse(read_text(dir_ / "summary.json"));
    EXPECT_EQ(summary["status"], "completed");
    EXPECT_GT(summary["duration"].get<double>(), 10.0);
    for (const auto& d : summary["drones"]) EXPECT_TRUE(d["landed"].get<bool>()) << d.dump();
    EXPECT_EQ((r.out + dex_logs()).find("forged by the test"), std::string::npos) << r.out << dex_logs();
  }
  fs::path dir_;
};

TEST_F(Security, CompileWritesEachDroneOnlyItsOwnPrivateKey) {
  compile("deploy");
  for (const char* d : {"Drone1", "Drone2", "Drone3", "ground-station"}) {
    fs::path folder = dir_ / "deploy" / d / "security";
    for (const char* f : kSecurityFiles) EXPECT_TRUE(fs::is_regular_file(folder / f)) << folder / f;
    EXPECT_EQ(fs::status(folder / "identity_key.pem").permissions() & fs::perms::all,
              fs::perms::owner_read | fs::perms::owner_write);
  }
  // One private key per folder (the CAs' keys are nowhere: made, used, thrown away).
  int keys = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir_ / "deploy"))
    if (read_text(e.path()).find("PRIVATE KEY") != std::string::npos) ++keys;
  EXPECT_EQ(keys, 4);
  // Another drone's key is not in this drone's folder.
  std::string key1 = read_text(dir_ / "deploy" / "Drone1" / "security" / "identity_key.pem");
  for (const auto& e : fs::recursive_directory_iterator(dir_ / "deploy" / "Drone2"))
    EXPECT_EQ(read_text(e.path()).find(key1), std::string::npos);
}

TEST_F(Security, SignaturesAndCertificatesVerifyWithTheOpensslTool) {
  // A second implementation's word on what pki.cpp wrote.
  compile("deploy");
  std::string folder = (dir_ / "deploy" / "Drone2" / "security").string();
  for (const char* doc : {"governance.p7s", "permissions.p7s"}) {
    std::string v = shell("openssl smime -verify -text -in " + folder + "/" + doc + " -CAfile " + folder +
                          "/permissions_ca.pem -out /dev/null");
    EXPECT_NE(v.find("Verification successful"), std::string::npos) << doc << ": " << v;
  }
  std::string v = shell("openssl verify -CAfile " + folder + "/identity_ca.pem " + folder + "/identity.pem");
  EXPECT_NE(v.find("identity.pem: OK"), std::string::npos) << v;
  EXPECT_NE(read_text(folder + "/permissions.p7s").find("CN=Drone2,O=eamos-mission-"), std::string::npos);
}

TEST_F(Security, KeysFolderIsMadeOnceAndSignsLaterCompilations) {
  Output first = eamos_test::run_eamos("compile -q " + source("listing2.eamos") + " -o " + (dir_ / "a").string() +
                                       " --keys " + (dir_ / "keys").string());
  ASSERT_EQ(first.status, 0) << first.out;
  EXPECT_NE(first.out.find("made a new identity CA"), std::string::npos) << first.out;
  Output second = eamos_test::run_eamos("compile -q " + source("listing2.eamos") + " -o " + (dir_ / "b").string() +
                                        " --keys " + (dir_ / "keys").string());
  ASSERT_EQ(second.status, 0) << second.out;
  EXPECT_NE(second.out.find("signed the mission's credentials with the CAs in"), std::string::npos) << second.out;
  EXPECT_EQ(read_text(dir_ / "a" / "Drone1" / "security" / "identity_ca.pem"),
            read_text(dir_ / "b" / "Drone1" / "security" / "identity_ca.pem"));
  EXPECT_EQ(fs::status(dir_ / "keys" / "identity_ca_key.pem").permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write);
  // Half a keys folder is refused, saying what is missing.
  fs::remove(dir_ / "keys" / "permissions_ca_key.pem");
  Output half = eamos_test::run_eamos("compile -q " + source("listing2.eamos") + " -o " + (dir_ / "c").string() +
                                      " --keys " + (dir_ / "keys").string());
  EXPECT_EQ(half.status, 1);
  EXPECT_NE(half.out.find("lacks permissions_ca_key.pem"), std::string::npos) << half.out;
}

TEST_F(Security, DexWithoutCredentialsRefusesToFlyUnlessInsecure) {
  compile("deploy", " --insecure");
  EXPECT_FALSE(fs::exists(dir_ / "deploy" / "Drone1" / "security"));
  Output r = eamos_test::run_eamos("dex " + (dir_ / "deploy" / "Drone1").string() + " --domain 150 --start-timeout 1");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("DDS Security credentials missing"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--insecure"), std::string::npos) << r.out;
  Output i = eamos_test::run_eamos("dex " + (dir_ / "deploy" / "Drone1").string() +
                                   " --domain 150 --start-timeout 1 --insecure");
  EXPECT_NE(i.out.find("WARNING: --insecure: DDS Security is OFF"), std::string::npos) << i.out;
}

TEST_F(Security, DroneCredentialsAllowWritingOnlyAsThatDrone) {
  std::string hash = compile("deploy");
  std::string folder = (dir_ / "deploy" / "Drone1" / "security").string();
  Attacker own(151, hash, 3);
  own.pose_as(0, folder);  // Drone1 as itself: allowed
  DdsOptions o;
  o.domain = 151;
  o.mission_hash = hash;
  o.self = 1;  // Drone1's credentials in Drone2's partition
  o.security_folder = folder;
  DdsHandlers h;
  h.limits.drones = 3;
  std::string error;
  auto node = DdsNode::open(o, std::move(h), error);
  EXPECT_EQ(node, nullptr);
  EXPECT_NE(error.find("cannot create DDS endpoints"), std::string::npos) << error;
}

TEST_F(Security, ParticipantWithoutCredentialsIsNotObeyed) {
  std::string hash = compile("deploy");
  Attacker attacker(152, hash, 3);
  for (int d = 0; d < 3; ++d) attacker.pose_as(d);
  Output r = launch(152, "", [&](std::uint64_t run) { attacker.forge_everything(run); });
  expect_flown_to_the_end(r);
}

TEST_F(Security, TheSameAttackIsObeyedWhenSecurityIsOff) {
  // What ParticipantWithoutCredentialsIsNotObeyed is measured against: with --insecure,
  // the forged ABORT (a well-formed one, from a drone of the mission) ends the run.
  std::string hash = compile("deploy");
  Attacker attacker(153, hash, 3);
  for (int d = 0; d < 3; ++d) attacker.pose_as(d);
  Output r = launch(153, " --insecure", [&](std::uint64_t run) { attacker.forge_everything(run); });
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE((r.out + dex_logs()).find("aborted by Drone2: forged by the test"), std::string::npos) << r.out;
}

TEST_F(Security, ParticipantWithAnotherCompilationsCredentialsIsNotObeyed) {
  // The same mission compiled again: same hash, same partitions, valid permissions for
  // them, but signed by other CAs. (One process holds one set of credentials per domain:
  // the attacker is that compilation's Drone2, and forges as Drone2.)
  std::string hash = compile("deploy");
  ASSERT_EQ(compile("other"), hash);
  Attacker attacker(154, hash, 3);
  attacker.pose_as(1, (dir_ / "other" / "Drone2" / "security").string());
  Output r = launch(154, "", [&](std::uint64_t run) {
    attacker.forge_abort(run, 1, {});
    attacker.forge_finished_from(run, 1);
  });
  expect_flown_to_the_end(r);
}

// --- with --insecure: the checks every DEX makes of every sample ---

TEST_F(Security, ForgedFinishedIsNotObeyedWhileDronesFly) {
  std::string hash = compile("deploy");
  Attacker attacker(155, hash, 3);
  for (int d = 0; d < 3; ++d) attacker.pose_as(d);
  Output r = launch(155, " --insecure", [&](std::uint64_t run) { attacker.forge_finished(run); });
  expect_flown_to_the_end(r);
  EXPECT_NE(dex_logs().find("ignored a finished sample from"), std::string::npos) << dex_logs();
}

TEST_F(Security, TriggerOfANodeThatDoesNotExistIsIgnoredAndNotCounted) {
  // Counted as received, it left Σsent ≠ Σreceived and the mission waiting until its limit.
  std::string hash = compile("deploy");
  Attacker attacker(156, hash, 3);
  attacker.pose_as(0);
  Output r = launch(
      156, " --insecure --time-limit 60", [&](std::uint64_t run) { attacker.forge_junk_trigger(run); }, true);
  expect_flown_to_the_end(r);
  EXPECT_NE(dex_logs().find("Drone2: ignored a trigger sample from Drone1: node 99999 of Drone1 is not in this drone's mission"),
            std::string::npos)
      << dex_logs();
}

TEST_F(Security, ReplayedTriggersAreDroppedBySequenceNumber) {
  std::string hash = compile("deploy");
  Attacker attacker(157, hash, 3);
  for (int d = 0; d < 3; ++d) attacker.pose_as(d, "", true);
  Output r = launch(157, " --insecure --time-limit 60", [](std::uint64_t) {}, true);
  expect_flown_to_the_end(r);
  EXPECT_GT(attacker.replayed(), 0u);
  EXPECT_NE(dex_logs().find("was already received"), std::string::npos) << dex_logs();
}

TEST_F(Security, AbortNamingADroneOutsideTheMissionIsIgnored) {
  std::string hash = compile("deploy");
  Attacker attacker(158, hash, 3);
  attacker.pose_as(1);
  Output r = launch(158, " --insecure", [&](std::uint64_t run) {
    attacker.forge_abort(run, 1, eamos::dex::Failure{"Drone99", "Takeoff", 3, "forged by the test"});
  });
  expect_flown_to_the_end(r);
  EXPECT_NE(dex_logs().find("the failed drone it names is not in the mission"), std::string::npos) << dex_logs();
}

}  // namespace
