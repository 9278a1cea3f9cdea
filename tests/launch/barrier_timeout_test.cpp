// The start barrier's default grows with the fleet (each participant discovers, and with DDS
// Security authenticates, every other one) and, with DDS Security, stays short of the
// instant Cyclone DDS gives a pending handshake up (where Debian 12's build can crash).
#include <gtest/gtest.h>

#include "launch/dex_process.h"
#include "launch/ground.h"
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
