#include "mid/event_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include "diag/log.h"

namespace eamos::mid {

namespace {
constexpr std::size_t kKeptBucketEntries = 64;

/// An index freed earlier when there is one, else a new element's at the end of `items`:
/// slots and buckets are reused so the loop allocates only when more are in use than ever.
template <class T>
std::uint32_t reuse_or_append(std::vector<T>& items, std::vector<std::uint32_t>& freed) {
  if (freed.empty()) {
    items.emplace_back();
    return static_cast<std::uint32_t>(items.size() - 1);
  }
  const std::uint32_t index = freed.back();
  freed.pop_back();
  return index;
}

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
  const std::uint32_t slot = reuse_or_append(slots_, free_slots_);
  Slot& s = slots_[slot];
  s.fn = std::move(fn);
  s.live = true;
  ++s.gen;  // a TimerId of the slot's earlier callback no longer names it
  ++live_;
  push(t, {slot, s.gen});
  return (static_cast<TimerId>(s.gen) << 32) | (static_cast<TimerId>(slot) + 1);
}

std::function<void()> EventLoop::take(std::uint32_t slot) {
  Slot& s = slots_[slot];
  std::function<void()> fn = std::move(s.fn);
  s.fn = nullptr;
  s.live = false;
  free_slots_.push_back(slot);
  --live_;
  return fn;
}

TimerId EventLoop::after(double dt, std::function<void()> fn) {
  return at(now_ + dt, std::move(fn));
}

TimerId EventLoop::defer(std::function<void()> fn) {
  double t = now_;
  if (options_.mode == ClockMode::real_time && running_) t = std::max(now_, wall_mission_time());
  return at(t, std::move(fn));
}

bool EventLoop::cancel(TimerId id) {
  if (id == kNoTimer || !live(slot_of(id), gen_of(id))) return false;
  take(slot_of(id));  // its heap entry stays and is skipped when popped: cancel is O(1)
  if (queued_ > 2 * live_ + 1024) compact();
  return true;
}

void EventLoop::push(double t, Entry e) {
  auto at = bucket_at_.find(t);
  if (at == bucket_at_.end()) {
    const std::uint32_t b = reuse_or_append(buckets_, free_buckets_);
    buckets_[b].time = t;
    at = add_time(t, b);
    heap_push(b);
  }
  buckets_[at->second].entries.push_back(e);
  ++queued_;
}

EventLoop::TimeBuckets::iterator EventLoop::add_time(double t, std::uint32_t bucket) {
  if (spare_times_.empty()) return bucket_at_.emplace(t, bucket).first;
  auto node = std::move(spare_times_.back());
  spare_times_.pop_back();
  node.key() = t;
  node.mapped() = bucket;
  return bucket_at_.insert(std::move(node)).position;
}

void EventLoop::drop_time(double t) {
  auto node = bucket_at_.extract(t);
  if (!node.empty()) spare_times_.push_back(std::move(node));
}

const EventLoop::Entry& EventLoop::front() const {
  const Bucket& b = buckets_[heap_.front()];
  return b.entries[b.head];
}

void EventLoop::pop() {
  const std::uint32_t top = heap_.front();
  Bucket& b = buckets_[top];
  --queued_;
  if (++b.head < b.entries.size()) {
    // An instant whose callbacks keep scheduling more at it (a cascade of zero-delay events)
    // drops what it has run now and then, so its bucket holds what is still to run.
    if (b.head >= 1024 && 2 * b.head >= b.entries.size()) {
      b.entries.erase(b.entries.begin(), b.entries.begin() + static_cast<std::ptrdiff_t>(b.head));
      b.head = 0;
    }
    return;
  }
  drop_time(b.time);
  // A small bucket keeps its capacity for the next time it is used; a large one (a fleet's
  // steps) gives it back: every bucket keeping the largest it ever held would hold memory
  // growing with the square of the fleet (timers in flight times drones stepping at once).
  if (b.entries.capacity() > kKeptBucketEntries) std::vector<Entry>().swap(b.entries);
  else b.entries.clear();
  b.head = 0;
  free_buckets_.push_back(top);
  heap_pop();
}

void EventLoop::heap_push(std::uint32_t bucket) {
  const double t = buckets_[bucket].time;
  std::size_t i = heap_.size();
  heap_.push_back(bucket);
  while (i > 0) {
    const std::size_t parent = (i - 1) / 4;
    if (!(t < buckets_[heap_[parent]].time)) break;
    heap_[i] = heap_[parent];
    i = parent;
  }
  heap_[i] = bucket;
}

void EventLoop::heap_pop() {
  const std::uint32_t last = heap_.back();
  heap_.pop_back();
  const std::size_t n = heap_.size();
  if (n == 0) return;
  const double t = buckets_[last].time;
  std::size_t i = 0;
  for (;;) {
    const std::size_t first = 4 * i + 1;
    if (first >= n) break;
    std::size_t best = first;
    const std::size_t end = std::min(first + 4, n);
    for (std::size_t c = first + 1; c < end; ++c)
      if (buckets_[heap_[c]].time < buckets_[heap_[best]].time) best = c;
    if (!(buckets_[heap_[best]].time < t)) break;
    heap_[i] = heap_[best];
    i = best;
  }
  heap_[i] = last;
}

void EventLoop::compact() {
  std::vector<std::uint32_t> queued = std::move(heap_);
  heap_.clear();
  queued_ = 0;
  for (std::uint32_t index : queued) {
    Bucket& b = buckets_[index];
    std::vector<Entry> kept;
    for (std::size_t i = b.head; i < b.entries.size(); ++i)
      if (live(b.entries[i].slot, b.entries[i].gen)) kept.push_back(b.entries[i]);
    b.head = 0;
    b.entries = std::move(kept);
    if (b.entries.empty()) {
      drop_time(b.time);
      free_buckets_.push_back(index);
      continue;
    }
    queued_ += b.entries.size();
    heap_push(index);
  }
}

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
  bool real = options_.mode == ClockMode::real_time;
  std::size_t ran = 0;
  running_ = true;
  while (!stop_requested_) {
    take_posted();
    while (!heap_.empty() && !live(front().slot, front().gen)) pop();  // cancelled
    // A real-time run bounded by `limit` waits for posted input until then, even when no
    // timer is due: that is how a DEX idles between messages.
    if (heap_.empty() || (bounded && front_time() > limit)) {
      if (bounded && real && !wait_for(limit)) continue;
      break;
    }
    const Entry next = front();
    const double next_time = front_time();
    if (!wait_for(next_time)) continue;
    if (real && stalled_before(next_time)) continue;  // the handler may have cancelled it
    if (real) max_lag_ = std::max(max_lag_, wall_mission_time() - next_time);
    pop();
    if (!live(next.slot, next.gen)) continue;
    // Take the callback out first: it may schedule or cancel timers, growing the slots.
    std::function<void()> fn = take(next.slot);
    now_ = std::max(now_, next_time);  // after a stall, overdue callbacks run at its end
    run_callback(fn);
    ++ran;
    ++events_run_;
  }
  running_ = false;
  return ran;
}

double EventLoop::wall_mission_time() const {
  return mission_anchor_ + (options_.wall->now_s() - wall_anchor_) * options_.speed;
}

bool EventLoop::stalled_before(double t) {
  if (!on_stall_) return false;
  double wall_now = options_.wall->now_s();
  double due = wall_anchor_ + (t - mission_anchor_) / options_.speed;
  double late = wall_now - std::max(due, caught_up_wall_);
  caught_up_wall_ = wall_now;
  if (!(late > stall_after_s_)) return false;
  now_ = std::max(now_, wall_mission_time());
  std::function<void()> fn = [this, late] { on_stall_(late); };
  run_callback(fn);
  ++events_run_;
  return true;
}

void EventLoop::run_callback(std::function<void()>& fn) noexcept {
  std::string what;
  try {
    fn();
    return;
  } catch (const std::exception& e) {
    what = e.what();
  } catch (...) {
    what = "an exception that is not a std::exception";
  }
  report_error(what);
}

void EventLoop::report_error(const std::string& what) noexcept {
  try {
    if (on_error_) return on_error_(what);
    diag::Logger{"mid", ""}.error("error in an event callback: " + what);
  } catch (...) {
    diag::Logger{"mid", ""}.error("error while handling an error in an event callback");
  }
}

void EventLoop::post(std::function<void()> fn) {
  {
    std::lock_guard<std::mutex> lock(post_mutex_);
    posted_.push_back(std::move(fn));
    has_posted_.store(true, std::memory_order_release);
  }
  post_cv_.notify_one();
}

void EventLoop::take_posted() {
  if (!has_posted_.load(std::memory_order_acquire)) return;
  std::vector<std::function<void()>> taken;
  {
    std::lock_guard<std::mutex> lock(post_mutex_);
    taken.swap(posted_);
    has_posted_.store(false, std::memory_order_relaxed);
  }
  if (taken.empty()) return;
  double t = now_;
  if (options_.mode == ClockMode::real_time) t = std::max(now_, wall_mission_time());
  // Input taken while the loop ran behind the wall clock got the wall's later mission time;
  // a later run anchors the clock at the loop's own time again (start_wall_anchor), which
  // would give what is posted then an earlier time than what is still queued. A vehicle's
  // frames must run in the order they came (an ACK's state before the HEARTBEAT after it).
  t = std::max(t, last_posted_at_);
  last_posted_at_ = t;
  for (auto& fn : taken) at(t, std::move(fn));
}

void EventLoop::start_wall_anchor() {
  // Anchor at the start of every run, so time spent outside the loop (compiling, loading)
  // is not "caught up" by running the first events late.
  if (options_.mode != ClockMode::real_time) return;
  caught_up_wall_ = options_.wall->now_s();
  if (wall_origin_) {
    wall_anchor_ = *wall_origin_;
    mission_anchor_ = 0.0;
    return;
  }
  wall_anchor_ = options_.wall->now_s();
  mission_anchor_ = now_;
}

bool EventLoop::wait_for(double t) {
  if (options_.mode != ClockMode::real_time) return true;
  double wall = wall_anchor_ + (t - mission_anchor_) / options_.speed;
  if (!(wall > options_.wall->now_s())) return true;
  if (options_.wall != &system_wall_clock()) {
    options_.wall->sleep_until_s(wall);  // a test's fake clock: nothing posts meanwhile
    return true;
  }
  using namespace std::chrono;
  auto deadline = steady_clock::time_point(duration_cast<steady_clock::duration>(duration<double>(wall)));
  std::unique_lock<std::mutex> lock(post_mutex_);
  return !post_cv_.wait_until(lock, deadline, [this] { return !posted_.empty(); });
}

}  // namespace eamos::mid
