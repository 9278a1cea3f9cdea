// The start barrier's default grows with the fleet (each participant discovers, and with DDS
// Security authenticates, every other one) and, with DDS Security, stays short of the
// instant Cyclone DDS gives a pending handshake up (where Debian 12's build can crash).
#include <gtest/gtest.h>

#include <string>

#include "launch/dex_process.h"
#include "launch/ground.h"
#include "loopback_config.h"
#include "transport/dds_node.h"

namespace {

using eamos::launch::barrier_timeout_for;

TEST(BarrierTimeout, ASmallFleetWaitsThirtySeconds) {
  EXPECT_DOUBLE_EQ(barrier_timeout_for(3, true), 30.0);
  EXPECT_DOUBLE_EQ(barrier_timeout_for(20, false), 30.0);
}

TEST(BarrierTimeout, ALargerFleetWaitsHalfASecondMorePerDrone) {
  EXPECT_DOUBLE_EQ(barrier_timeout_for(50, true), 45.0);
  EXPECT_DOUBLE_EQ(barrier_timeout_for(100, false), 70.0);
  EXPECT_DOUBLE_EQ(barrier_timeout_for(1000, false), 520.0);
}

TEST(BarrierTimeout, ASecureBarrierEndsBeforeCycloneGivesAHandshakeUp) {
  EXPECT_DOUBLE_EQ(barrier_timeout_for(1000, true), eamos::launch::kMaxSecureBarrierS);
  // Every DEX the launch starts waits for the start 5 s longer than the barrier.
  EXPECT_LT(eamos::launch::kMaxSecureBarrierS + 5.0, eamos::transport::kHandshakeGiveUpS);
  EXPECT_LT(eamos::launch::kSecureUnreadyLimitS, eamos::transport::kHandshakeGiveUpS);
}

}  // namespace

namespace {

// Every DEX and the ground is a participant with an automatic index of its own on one host:
// with fewer indices than 101, the 100th DEX of a 100-drone launch cannot join DDS.
TEST(LoopbackConfiguration, AHundredDronesAndTheGroundEachFindAParticipantIndex) {
  std::string xml = eamos::transport::kLoopbackConfig;
  const std::string tag = "<MaxAutoParticipantIndex>";
  auto at = xml.find(tag);
  ASSERT_NE(at, std::string::npos) << xml;
  EXPECT_GE(std::stoi(xml.substr(at + tag.size())) + 1, 101) << xml;
}

}  // namespace
