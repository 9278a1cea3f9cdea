#include "mid/event_loop.h"

#include <chrono>
#include <cmath>
#include <thread>

namespace eamos::mid {

namespace {
class SteadyWallClock final : public WallClock {
 public:
  double now_s() override {
    using namespace std::chrono;
    return duration<double>(steady_clock::now().time_since_epoch()).count();
  }
  void sleep_until_s(double t) override {
    using namespace std::chrono;
    std::this_thread::sleep_until(
        steady_clock::time_point(duration_cast<steady_clock::duration>(duration<double>(t))));
  }
};
}  // namespace

WallClock& system_wall_clock() {
  static SteadyWallClock clock;
  return clock;
}

EventLoop::EventLoop(ClockOptions options) : options_(options) {
  if (!options_.wall) options_.wall = &system_wall_clock();
  if (!(options_.speed > 0.0)) options_.speed = 1.0;
}

TimerId EventLoop::at(double t, std::function<void()> fn) {
  if (!std::isfinite(t)) return kNoTimer;
  if (t < now_) t = now_;
  std::uint64_t seq = next_seq_++;
  queue_.push({t, seq});
  callbacks_.emplace(seq, std::move(fn));
  return seq;
}

TimerId EventLoop::after(double dt, std::function<void()> fn) {
  return at(now_ + dt, std::move(fn));
}

bool EventLoop::cancel(TimerId id) { return callbacks_.erase(id) != 0; }

std::size_t EventLoop::run_until_idle() {
  std::size_t ran = run(0.0, false);
  stop_requested_ = false;
  return ran;
}

std::size_t EventLoop::run_until(double t) {
  std::size_t ran = run(t, true);
  if (!stop_requested_ && t > now_) {
    wait_for(t);
    now_ = t;
  }
  stop_requested_ = false;
  return ran;
}

std::size_t EventLoop::run(double limit, bool bounded) {
  stop_requested_ = false;
  start_wall_anchor();
  std::size_t ran = 0;
  while (!queue_.empty() && !stop_requested_) {
    Entry next = queue_.top();
    if (bounded && next.time > limit) break;
    queue_.pop();
    auto it = callbacks_.find(next.seq);
    if (it == callbacks_.end()) continue;  // cancelled
    // Take the callback out first: it may schedule or cancel timers, rehashing the map.
    std::function<void()> fn = std::move(it->second);
    callbacks_.erase(it);
    wait_for(next.time);
    now_ = next.time;
    fn();
    ++ran;
    ++events_run_;
  }
  return ran;
}

void EventLoop::start_wall_anchor() {
  // Anchor at the start of every run, so time spent outside the loop (compiling, loading)
  // is not "caught up" by running the first events late.
  if (options_.mode != ClockMode::real_time) return;
  wall_anchor_ = options_.wall->now_s();
  mission_anchor_ = now_;
}

void EventLoop::wait_for(double t) {
  if (options_.mode != ClockMode::real_time) return;
  double wall = wall_anchor_ + (t - mission_anchor_) / options_.speed;
  if (wall > options_.wall->now_s()) options_.wall->sleep_until_s(wall);
}

}  // namespace eamos::mid
