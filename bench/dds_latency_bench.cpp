// Cross-drone trigger latency over DDS on loopback: drone A's OutBridge writes a trigger
// (as DdsTransport::send does), drone B's InBridge gets it on a DDS thread and posts it to
// B's event loop, whose callback answers at once; the answer takes the same way back to
// A's loop. Half the round trip is the latency from "node ends on A" to "B's engine has
// the trigger on its loop thread". B is a separate process (forked before DDS starts), on
// the shipped loopback configuration: the same transport `ddsperf ping/pong` measures when
// scripts/bench.sh points it at config/cyclonedds-loopback.xml.
#include <benchmark/benchmark.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "mid/event_loop.h"
#include "transport/dds_node.h"

namespace {

using namespace eamos;
constexpr int kDomain = 62;

transport::TriggerSample trigger(int to, std::uint64_t seq) {
  transport::TriggerSample s;
  s.run_id = 1;
  s.to = to;
  s.seq = seq;
  s.message.mission_hash = "bench";
  s.message.from = 1 - to;
  return s;
}

/// Drone B: answers every trigger addressed to it from its event loop, until killed.
[[noreturn]] void pong() {
  mid::EventLoop loop({mid::ClockMode::real_time, 1.0, nullptr});
  transport::DdsNode* self = nullptr;
  transport::DdsHandlers h;
  h.trigger = [&](transport::TriggerSample s) {
    if (s.to != 1) return;
    loop.post([&, seq = s.seq] { self->write(trigger(0, seq)); });
  };
  std::string error;
  transport::DdsOptions o;
  o.domain = kDomain;
  auto node = transport::DdsNode::open(o, h, error);
  if (!node) _exit(1);
  self = node.get();
  for (;;) loop.run_until(loop.now() + 3600.0);
}

void BM_CrossDroneTriggerLatency(benchmark::State& state) {
  pid_t child = fork();
  if (child == 0) pong();
  mid::EventLoop loop({mid::ClockMode::real_time, 1.0, nullptr});
  std::uint64_t expected = 0;
  transport::DdsHandlers h;
  h.trigger = [&](transport::TriggerSample s) {
    if (s.to != 0) return;
    loop.post([&, seq = s.seq] {
      if (seq == expected) loop.stop();
    });
  };
  std::string error;
  transport::DdsOptions o;
  o.domain = kDomain;
  auto node = transport::DdsNode::open(o, h, error);
  if (!node) {
    state.SkipWithError(error.c_str());
    kill(child, SIGKILL);
    return;
  }
  // Warm up: the first answer also waits for discovery.
  for (int i = 0; i < 100; ++i) {
    expected = i + 1;
    node->write(trigger(1, expected));
    loop.run_until(loop.now() + 30.0);
  }
  std::vector<double> one_way_us;
  for (auto _ : state) {
    expected += 1;
    auto t0 = std::chrono::steady_clock::now();
    node->write(trigger(1, expected));
    loop.run_until(loop.now() + 30.0);
    double rtt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.SetIterationTime(rtt / 2);
    one_way_us.push_back(rtt / 2 * 1e6);
  }
  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  node.reset();
  std::sort(one_way_us.begin(), one_way_us.end());
  auto pct = [&](double p) { return one_way_us[static_cast<std::size_t>(p * (one_way_us.size() - 1))]; };
  state.counters["median_us"] = pct(0.5);
  state.counters["p90_us"] = pct(0.9);
  state.counters["p99_us"] = pct(0.99);
  state.counters["max_us"] = one_way_us.back();
}
BENCHMARK(BM_CrossDroneTriggerLatency)->UseManualTime()->Iterations(20000)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
