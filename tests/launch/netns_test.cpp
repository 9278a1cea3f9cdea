// A bad network between the drones: each DEX and the ground in a
// network namespace of its own, created here, connected to the others only through
// eamos-udp-relay (tests/support/udp_relay.cpp), which loses, delays, jitters and cuts
// Cyclone DDS's unicast traffic (the kernel here has no netem). Each participant's Cyclone
// configuration fixes its participant index (so its ports), binds its namespace's veth and
// advertises the relay's side of it, so every datagram goes through the relay.
// The mission (tests/launch/missions/hops.eamos) is a chain of cross-drone triggers whose
// per-drone order does not depend on timing. Expected: it completes with the in-process
// per-drone order, or every drone is in its failsafe within the liveliness lease.
// Needs root and `ip netns` (CI runs as root); skipped with a message otherwise. DDS
// domains 170-179. Nothing sleeps: the tests act on the processes' output lines, a timed
// cut is the relay's own timer.
#include "netns_fixture.h"

namespace {

using namespace netns_support;

TEST_F(Netns, TenPercentLossCompletesInTheSameOrder) {
  domain_ = 170;
  lease_ = "2";
  expect_completes_in_order({"--loss", "0.1", "--seed", "1"}, false);
}

TEST_F(Netns, ThirtyPercentLossCompletesInTheSameOrder) {
  // At this loss a DDS Security handshake fails for good (docs/faults.md): refused at the
  // barrier even after 90 s (measured), so a 10 s barrier decides as well as 20 s did.
  domain_ = 171;
  lease_ = "2";
  barrier_timeout_ = "10";
  expect_completes_in_order({"--loss", "0.3", "--seed", "2"}, false);
}

TEST_F(Netns, FiftyMillisecondsDelayWithTenOfJitterCompletesInTheSameOrder) {
  domain_ = 172;
  lease_ = "2";
  expect_completes_in_order({"--delay", "0.05", "--jitter", "0.01", "--seed", "3"}, true);
}

TEST_F(Netns, TwoSecondCutOfOneDronePutsEveryDroneInItsFailsafeWithinTheLease) {
  domain_ = 173;
  expect_failsafe_within_lease_after_cut(2.0);
}

TEST_F(Netns, PermanentCutOfOneDronePutsEveryDroneInItsFailsafeWithinTheLease) {
  domain_ = 174;
  expect_failsafe_within_lease_after_cut(0.0);
}

}  // namespace
