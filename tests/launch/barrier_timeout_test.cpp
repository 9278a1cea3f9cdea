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

// A small fleet starts at once; a larger one in waves of the default size, smaller with
// DDS Security (each joining DEX authenticates with every participant already there).
TEST(StartWave, AFleetUpToTheWaveSizeStartsAtOnceALargerOneInWaves) {
  using eamos::launch::start_wave_for;
  EXPECT_EQ(start_wave_for(3, true), 3);
  EXPECT_EQ(start_wave_for(eamos::launch::kSecureStartWave, true), eamos::launch::kSecureStartWave);
  EXPECT_EQ(start_wave_for(50, true), eamos::launch::kSecureStartWave);
  EXPECT_EQ(start_wave_for(51, true), eamos::launch::kLargeSecureStartWave);
  EXPECT_EQ(start_wave_for(100, true), eamos::launch::kLargeSecureStartWave);
  EXPECT_EQ(start_wave_for(100, false), eamos::launch::kInsecureStartWave);
  EXPECT_LT(eamos::launch::kSecureStartWave, eamos::launch::kInsecureStartWave);
  EXPECT_EQ(start_wave_for(0, true), 1);
}

// Every drone's state goes to every other drone: the fleet's telemetry grows with the
// square of its size, so beyond twenty drones each publishes less often.
TEST(StateRate, UpToTwentyDronesEveryChangeIsPublishedBeyondTheRateFallsWithTheSquareOfTheFleet) {
  using eamos::launch::state_rate_for;
  EXPECT_DOUBLE_EQ(state_rate_for(3), eamos::launch::kFullStateRateHz);
  EXPECT_DOUBLE_EQ(state_rate_for(20), eamos::launch::kFullStateRateHz);
  EXPECT_DOUBLE_EQ(state_rate_for(40), 5.0);
  EXPECT_DOUBLE_EQ(state_rate_for(100), 1.0);   // 0.8 by the square, at least 1
  EXPECT_DOUBLE_EQ(state_rate_for(1000), 1.0);
}

// Every drone receives every other drone's arrival at a barrier: beyond twenty drones a
// status whose only news is its trigger counters waits for a quarter of the lease, while a
// change of busy, phase, end or wave still goes out at once.
TEST(StatusRate, BeyondTwentyDronesAChangeOfCountersAloneIsCoalescedOtherChangesAreNot) {
  using eamos::launch::counters_gap_for;
  using eamos::launch::status_change;
  using eamos::launch::StatusChange;
  EXPECT_DOUBLE_EQ(counters_gap_for(20, 2.0), 0.0);
  EXPECT_DOUBLE_EQ(counters_gap_for(21, 2.0), 0.5);
  EXPECT_DOUBLE_EQ(counters_gap_for(100, 10.0), 2.5);
  eamos::transport::StatusSample before;
  before.sent = 3;
  before.received = 7;
  eamos::transport::StatusSample now = before;
  EXPECT_EQ(status_change(before, now), StatusChange::none);
  now.received = 8;
  EXPECT_EQ(status_change(before, now), StatusChange::counters);
  now.sent = 4;
  EXPECT_EQ(status_change(before, now), StatusChange::counters);
  now.busy = true;
  EXPECT_EQ(status_change(before, now), StatusChange::other);
  now = before;
  now.wave = 1;
  EXPECT_EQ(status_change(before, now), StatusChange::other);
  now = before;
  now.phase = eamos::transport::Phase::completed;
  EXPECT_EQ(status_change(before, now), StatusChange::other);
}

}  // namespace

namespace {

// With an automatic participant index each DEX and the ground needs one of a bounded range on
// one host (Cyclone's default 9): the 100th DEX of a 100-drone launch could not join DDS.
// Discovered by multicast, a participant needs none.
TEST(LoopbackConfiguration, AHundredDronesAndTheGroundJoinWithoutAParticipantIndex) {
  std::string xml = eamos::transport::kLoopbackConfig;
  EXPECT_NE(xml.find("<ParticipantIndex>none</ParticipantIndex>"), std::string::npos) << xml;
  EXPECT_EQ(xml.find("<MaxAutoParticipantIndex>"), std::string::npos) << xml;
}

}  // namespace
