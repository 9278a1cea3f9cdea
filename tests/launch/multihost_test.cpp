// A fleet over two machines: two network namespaces joined by one veth pair stand for two
// hosts on one network. Host A runs the ground and Drone1's DEX (`eamos launch --drones
// Drone1`), host B the DEXes of Drone2 and Drone3 (`eamos dex`, as on their companions),
// all with DDS Security and the shipped config/cyclonedds-hosts.xml: no multicast, the
// interface named by EAMOS_DDS_INTERFACE, both hosts' addresses as peers (the only edit).
// Expected: the mission completes with the in-process per-drone order. Needs root and
// `ip netns` (CI runs as root); skipped with a message otherwise. DDS domain 177. Nothing
// sleeps: the test waits for the processes' exits.
#include "netns_fixture.h"

#include <cstdlib>

namespace {

using namespace netns_support;

class MultiHost : public ::testing::Test {
 protected:
  void SetUp() override {
    if (geteuid() != 0) GTEST_SKIP() << "network namespace tests need root (CI runs them as root)";
    if (sh("ip netns list") != 0) GTEST_SKIP() << "no `ip netns` (iproute2) here";
    prefix_ = "emh" + std::to_string(getpid() % 100000);
    int net = 100 + getpid() % 100;
    dir_ = fs::temp_directory_path() / (prefix_ + "-multihost");
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    for (int h : {0, 1}) address_[h] = "10." + std::to_string(net) + ".200." + std::to_string(h + 1);
    bool ok = sh("ip netns add " + ns(0)) == 0 && sh("ip netns add " + ns(1)) == 0;
    made_ = true;
    ok = ok && sh("ip link add " + veth(0) + " type veth peer name " + veth(1)) == 0;
    for (int h : {0, 1})
      ok = ok && sh("ip link set " + veth(h) + " netns " + ns(h)) == 0 &&
           sh("ip -n " + ns(h) + " addr add " + address_[h] + "/24 dev " + veth(h)) == 0 &&
           sh("ip -n " + ns(h) + " link set " + veth(h) + " up") == 0 && sh("ip -n " + ns(h) + " link set lo up") == 0;
    if (!ok) GTEST_SKIP() << "cannot create two network namespaces joined by a veth pair";
    write_config();
    Output c = eamos_test::run_eamos("compile -q " + std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos -o " +
                                     (dir_ / "deploy").string());
    ASSERT_EQ(c.status, 0) << c.out;
  }
  void TearDown() override {
    if (made_)
      for (int h : {0, 1}) sh("ip netns del " + ns(h));  // deleting a namespace deletes its end of the veth
    if (!HasFailure() && !dir_.empty()) fs::remove_all(dir_);
  }
  using Output = eamos_test::Output;

  std::string ns(int h) const { return prefix_ + "-" + std::to_string(h); }
  std::string veth(int h) const { return prefix_ + "v" + std::to_string(h); }

  /// The shipped file with the two example peers replaced by the two hosts' addresses.
  void write_config() {
    std::string xml = read_text(std::string(EAMOS_SOURCE_DIR) + "/config/cyclonedds-hosts.xml");
    for (auto [example, real] : {std::pair{"192.168.10.1", address_[0]}, std::pair{"192.168.10.2", address_[1]}}) {
      auto at = xml.find(example);
      ASSERT_NE(at, std::string::npos) << xml;
      xml.replace(at, std::string(example).size(), real);
    }
    std::ofstream(dir_ / "cyclonedds.xml") << xml;
  }

  /// `args` run in host h's namespace with EAMOS_DDS_INTERFACE naming its veth.
  std::vector<std::string> on_host(int h, std::vector<std::string> args) const {
    std::vector<std::string> all = {"ip", "netns", "exec", ns(h), "env", "EAMOS_DDS_INTERFACE=" + veth(h), EAMOS_BINARY};
    all.insert(all.end(), args.begin(), args.end());
    return all;
  }

  std::string prefix_;
  std::string address_[2];
  fs::path dir_;
  bool made_ = false;
};

TEST_F(MultiHost, DexesOnTwoHostsCompleteTheMissionWithTheConfigurationForSeveralMachines) {
  Output local = eamos_test::run_eamos("run -q " + std::string(EAMOS_SOURCE_DIR) + "/examples/listing2.eamos --trace " +
                                       (dir_ / "local.jsonl").string());
  ASSERT_EQ(local.status, 0) << local.out;
  const std::string config = (dir_ / "cyclonedds.xml").string();
  const std::vector<std::string> common = {"--domain", "177", "--speed", "5", "--dds-config", config};
  std::vector<Child> dexes;
  for (std::string drone : {"Drone2", "Drone3"}) {
    std::vector<std::string> args = {"dex", (dir_ / "deploy" / drone).string(), "--start-timeout", "60"};
    args.insert(args.end(), common.begin(), common.end());
    dexes.push_back(start(on_host(1, args), (dir_ / (drone + ".log")).string()));
  }
  std::vector<std::string> args = {"launch", (dir_ / "deploy").string(), "--drones", "Drone1", "--barrier-timeout", "55",
                                   "--trace", (dir_ / "trace.jsonl").string()};
  args.insert(args.end(), common.begin(), common.end());
  Child ground = start(on_host(0, args));
  int status = wait_exit(ground);
  std::string logs = "ground:\n" + ground.seen;
  std::vector<int> dex_status;
  for (Child& c : dexes) dex_status.push_back(wait_exit(c));
  for (std::string drone : {"Drone2", "Drone3"}) logs += drone + ":\n" + read_text(dir_ / (drone + ".log"));
  ASSERT_EQ(status, 0) << logs;
  for (int s : dex_status) EXPECT_EQ(s, 0) << logs;
  EXPECT_EQ(per_drone(dir_ / "trace.jsonl"), per_drone(dir_ / "local.jsonl")) << logs;
  // Drone1 flew on host A, the others on host B: the ground started only Drone1's DEX.
  EXPECT_NE(ground.seen.find("started the DEX of Drone1"), std::string::npos) << logs;
  EXPECT_EQ(ground.seen.find("started the DEX of Drone2"), std::string::npos) << logs;
}

}  // namespace
