// The latency figures of the ground's summary (src/dex/latency.h): which messages count, the
// maximum, the nearest-rank 99th percentile and the list of late ones.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "dex/latency.h"

namespace eamos::dex {
namespace {

TraceEvent message(const std::string& kind, int from, int to, double sent, double received) {
  TraceEvent e;
  e.event = "message";
  e.kind = kind;
  e.from = from;
  e.to = to;
  e.node = 7;
  e.sent = sent;
  e.t = received;
  return e;
}

const std::vector<std::string> kFleet = {"A", "B"};

TEST(MessageLatency, P99IsTheNearestRankAndOnlyMessagesAboveTheBoundAreLate) {
  std::vector<TraceEvent> events;
  // 100 triggers 0.01 … 1.00 s late: 99 % are at most 0.99 s late.
  for (int k = 1; k <= 100; ++k) events.push_back(message("trigger", 0, 1, 10.0, 10.0 + k / 100.0));
  MessageLatency m = message_latency(events, kFleet, 0.975);
  EXPECT_EQ(m.count, 100u);
  EXPECT_NEAR(m.max_s, 1.00, 1e-9);
  EXPECT_NEAR(m.p99_s, 0.99, 1e-9);
  ASSERT_EQ(m.late.size(), 3u);  // 0.98, 0.99, 1.00
  EXPECT_EQ(m.late[0].from, "A");
  EXPECT_EQ(m.late[0].to, "B");
  EXPECT_EQ(m.late[0].node, 7);
  EXPECT_NEAR(m.late[0].latency, 0.98, 1e-9);
  EXPECT_EQ(describe_late(m.late[0]), "trigger from A to B (node 7) was received 0.980 mission s after it was sent "
                                      "at 10.000 s");
}

TEST(MessageLatency, FinishedAbortAndOtherEventsDoNotCount) {
  TraceEvent abort = message("abort", -1, -1, 1.0, 9.0);  // from the ground, to every drone
  TraceEvent finished = message("finished", 0, -1, 1.0, 9.0);
  TraceEvent start = message("trigger", 0, 1, 1.0, 9.0);
  start.event = "start";
  MessageLatency m = message_latency({abort, finished, start, message("cancel", 1, 0, 2.0, 2.5)}, kFleet, 0.1);
  EXPECT_EQ(m.count, 1u);
  EXPECT_NEAR(m.max_s, 0.5, 1e-9);
  EXPECT_NEAR(m.p99_s, 0.5, 1e-9);
  ASSERT_EQ(m.late.size(), 1u);
  EXPECT_EQ(m.late[0].kind, "cancel");
  EXPECT_EQ(message_latency({}, kFleet, 0.5).count, 0u);
}

}  // namespace
}  // namespace eamos::dex
