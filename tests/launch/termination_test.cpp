// Termination detection (launch/termination.h): two consecutive clean waves with the same
// sums end the mission; a message in flight, delivered late or out of order, never lets a
// wave pair pass, including the case that fools "every drone idle and Σsent = Σreceived".
#include <gtest/gtest.h>

#include "launch/termination.h"

namespace eamos::launch {
namespace {

/// A fleet of drones whose counters the test moves by hand: a message is "sent" when its
/// sender's count goes up and "delivered" when its receiver's does.
struct Fleet {
  std::vector<WaveReport> now;
  explicit Fleet(int n) : now(n) {
    for (int d = 0; d < n; ++d) now[d].drone = d;
  }
  void answer(TerminationDetector& t, int d) {
    WaveReport r = now[d];
    r.wave = t.wave();
    t.report(r);
  }
  void answer_all(TerminationDetector& t) {
    for (int d = 0; d < static_cast<int>(now.size()); ++d) answer(t, d);
  }
};

TEST(Termination, TwoCleanWavesWithTheSameSumsEndTheMission) {
  TerminationDetector t(3);
  Fleet f(3);
  f.now[0].sent = 2, f.now[1].received = 1, f.now[2].received = 1;
  t.start_wave();
  f.answer_all(t);
  EXPECT_FALSE(t.terminated()) << "one wave is not enough";
  t.start_wave();
  f.answer_all(t);
  EXPECT_TRUE(t.terminated());
}

TEST(Termination, AWaveMissingAnAnswerDecidesNothing) {
  TerminationDetector t(3);
  Fleet f(3);
  t.start_wave();
  f.answer_all(t);
  t.start_wave();
  f.answer(t, 0);
  f.answer(t, 1);
  EXPECT_TRUE(t.collecting());
  EXPECT_FALSE(t.terminated());
}

// The counterexample to a single snapshot: drone 1 reports (sent 0), then sends m1 to drone
// 2; drone 2 receives m1 and reports (received 1); meanwhile drone 0's message m0 to drone 1,
// sent before drone 0 reported, is still on its way. The snapshot reads Σsent = 1 (m0) and
// Σreceived = 1 (m1), every drone idle: equal, yet m0 is in flight.
TEST(Termination, AMessageInFlightBalancedByAnotherIsNotMistakenForTheEnd) {
  TerminationDetector t(3);
  Fleet f(3);
  f.now[0].sent = 1;      // m0 sent, not yet delivered
  t.start_wave();
  f.answer(t, 0);
  f.answer(t, 1);         // drone 1 reports sent 0
  f.now[1].sent = 1;      // then sends m1
  f.now[2].received = 1;  // drone 2 receives m1 before it reports
  f.answer(t, 2);
  ASSERT_TRUE(t.wave_complete());
  t.start_wave();         // m0 still in flight: drone 1 has not received it
  f.answer_all(t);
  EXPECT_FALSE(t.terminated()) << "Σsent 2 ≠ Σreceived 1 in the second wave";
  f.now[1].received = 1;  // m0 arrives late
  t.start_wave();
  f.answer_all(t);
  EXPECT_FALSE(t.terminated()) << "its previous wave was not clean";
  t.start_wave();
  f.answer_all(t);
  EXPECT_TRUE(t.terminated());
}

// A message delivered between the waves makes its receiver busy or changes the sums: the
// first wave may look clean, the second differs, so the pair does not pass.
TEST(Termination, AMessageDeliveredBetweenTheWavesRestartsTheCount) {
  TerminationDetector t(2);
  Fleet f(2);
  t.start_wave();
  f.answer_all(t);        // clean: nothing sent yet
  f.now[0].sent = 1;      // drone 0 (answered idle) was woken and sent to drone 1
  f.now[1].received = 1;  // which took it and is busy with it
  f.now[1].busy = true;
  t.start_wave();
  f.answer_all(t);
  EXPECT_FALSE(t.terminated());
  f.now[1].busy = false;
  t.start_wave();
  f.answer_all(t);
  EXPECT_FALSE(t.terminated()) << "the sums changed since the last clean wave";
  t.start_wave();
  f.answer_all(t);
  EXPECT_TRUE(t.terminated());
}

TEST(Termination, OnlyTheFirstAnswerToAWaveCountsAndLateAnswersToOldWavesAreIgnored) {
  TerminationDetector t(2);
  Fleet f(2);
  std::uint64_t first = t.start_wave();
  f.answer_all(t);
  t.start_wave();
  t.report({0, first, true, 5, 0});  // a late answer to the first wave
  f.answer(t, 0);
  f.answer(t, 1);
  t.report({1, t.wave(), true, 9, 0});  // a second answer to this wave: ignored
  EXPECT_TRUE(t.terminated());
}

TEST(Termination, AResetNeedsTwoNewWaves) {
  TerminationDetector t(2);
  Fleet f(2);
  t.start_wave();
  f.answer_all(t);
  t.reset();  // the lead saw a drone busy
  EXPECT_FALSE(t.collecting());
  t.start_wave();
  f.answer_all(t);
  EXPECT_FALSE(t.terminated());
  t.start_wave();
  f.answer_all(t);
  EXPECT_TRUE(t.terminated());
}

}  // namespace
}  // namespace eamos::launch
