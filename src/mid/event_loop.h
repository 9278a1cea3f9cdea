#pragma once
// The executor's clock: one thread runs timed callbacks in time order. Nothing in the
// execution stack owns a thread or polls; a drone's motion, an action's timeout and a
// PauseFor are all timers here. Virtual time (tests, default runs) jumps from event to
// event, so a 60 s mission takes as long as its callbacks; real time (the CLI's
// --realtime/--speed) sleeps until each event's wall time.
#include <atomic>
#include <bit>
#include <cstdint>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace eamos::mid {

/// Identifies one scheduled callback; 0 (kNoTimer) is never issued.
using TimerId = std::uint64_t;
inline constexpr TimerId kNoTimer = 0;

/// The wall time source of real-time mode. Tests substitute a fake that records sleeps, so
/// no test ever sleeps.
class WallClock {
 public:
  virtual ~WallClock() = default;
  virtual double now_s() = 0;                ///< seconds since an arbitrary epoch
  virtual void sleep_until_s(double t) = 0;  ///< returns at or after wall time t
};
/// std::chrono::steady_clock and std::this_thread::sleep_until.
WallClock& system_wall_clock();

enum class ClockMode {
  virtual_time,  ///< jump to the next event at once
  real_time,     ///< wait until the wall time of the next event (scaled by `speed`)
};

struct ClockOptions {
  ClockMode mode = ClockMode::virtual_time;
  double speed = 1.0;          ///< real time only: 2 = mission time runs twice as fast as wall
  WallClock* wall = nullptr;   ///< real time only: nullptr = system_wall_clock()
};

class EventLoop {
 public:
  explicit EventLoop(ClockOptions options = {});
  EventLoop(const EventLoop&) = delete;
  EventLoop& operator=(const EventLoop&) = delete;

  /// Mission time in seconds: 0 at construction, the time of the running event during a
  /// callback, the time reached after run_until(t).
  double now() const { return now_; }

  /// Schedules `fn` at mission time `t` (a time in the past means now). Callbacks with equal
  /// times run in the order they were scheduled. A non-finite `t` schedules nothing and
  /// returns kNoTimer.
  TimerId at(double t, std::function<void()> fn);
  /// at(now() + dt, fn).
  TimerId after(double dt, std::function<void()> fn);
  /// Schedules `fn` behind everything already due, so that work which takes no mission time
  /// (a loop iteration) cannot starve the rest: on virtual time at now(); on real time, while
  /// the loop runs, at the mission time the wall clock shows now, so input that I/O threads
  /// posted meanwhile (DDS samples, MAVLink frames, signals) and due timers run first.
  TimerId defer(std::function<void()> fn);
  /// Unschedules a pending callback; false when it already ran, was cancelled or is unknown.
  bool cancel(TimerId id);
  bool pending(TimerId id) const { return live(slot_of(id), gen_of(id)); }
  /// Number of callbacks still scheduled.
  std::size_t size() const { return live_; }

  /// Runs callbacks until none is scheduled or stop() was called; returns how many ran.
  /// Something that reschedules itself forever (an endless Orbit) keeps it from returning:
  /// bound such runs with run_until.
  std::size_t run_until_idle();
  /// Runs every callback scheduled at or before `t`, then sets now() to `t` (unless stop()
  /// was called first); returns how many ran.
  std::size_t run_until(double t);
  /// Makes the running run_until_idle/run_until return after the current callback.
  void stop() { stop_requested_ = true; }

  /// The one thread-safe call: runs `fn` on the loop's thread as soon as the loop gets to
  /// it, at the mission time of that moment. I/O threads (a DDS listener, a MAVLink socket
  /// reader) hand their input over this way, so adapter and engine state is only ever
  /// touched by the loop's thread. A real-time loop waiting for its next timer wakes up.
  void post(std::function<void()> fn);

  /// Real time: mission time 0 happens at steady wall time `wall_s` (system_wall_clock's
  /// seconds), for every run of this loop, instead of "when run() is called". Processes
  /// that share a start instant share their mission clock this way.
  void set_wall_origin(double wall_s) { wall_origin_ = wall_s; }

  /// A callback that throws does not end the loop (and with it a process whose drones are in
  /// the air): the exception is caught, `handler` gets its message, and the loop goes on
  /// with the next callback. The DEX abandons the mission into the failsafe there. Without
  /// a handler the message goes to standard error. A handler that throws is logged too.
  void on_callback_error(std::function<void(const std::string& what)> handler) { on_error_ = std::move(handler); }

  /// Real time only: when the loop finds its next callback due more than `after_s` wall
  /// seconds ago although the loop was already running then (the process was stopped with
  /// SIGSTOP, swapped out, or starved), `handler` runs first, at the mission time the wall
  /// clock shows now (not back-dated), with how many wall seconds the loop stalled. Only
  /// then do the overdue callbacks run (at that mission time, in their order), so the
  /// handler can cancel what must not happen late (a DEX halts its mission). What was due
  /// before run() began is a catch-up (a late start), not a stall.
  void on_stall(double after_s, std::function<void(double stalled_s)> handler) {
    stall_after_s_ = after_s;
    on_stall_ = std::move(handler);
  }

  /// Real time only: the most mission time by which a callback ran later than its time,
  /// because the loop was still busy when the wall clock reached it (the host cannot follow
  /// `speed`) or stalled; 0 on virtual time. Work deferred meanwhile (defer, post) takes the
  /// wall's mission time, so this much is how far a run's timing may stray from the plan's.
  double max_lag() const { return max_lag_; }

  /// Callbacks run since construction (a cost measure: idle drones must not add to it).
  std::uint64_t events_run() const { return events_run_; }
  /// Entries the queue holds, cancelled ones included (they leave it when due, or all at
  /// once when they outnumber the live ones): what the loop's memory grows with.
  std::size_t queued() const { return queued_; }
  /// Entries the buckets have room for, used or not: the queue's memory beside queued().
  std::size_t queue_room() const {
    std::size_t room = 0;
    for (const Bucket& b : buckets_) room += b.entries.capacity();
    return room;
  }

 private:
  struct Entry {
    std::uint32_t slot;
    std::uint32_t gen;
  };
  /// Every entry due at one time, in scheduling order (appending keeps it: later calls come
  /// later). Callbacks with equal times run in the order scheduled, so the queue is ordered
  /// by time across buckets and by position within one: a fleet whose drones step at the
  /// same instants (every drone that passed a barrier together) pops its steps from one
  /// bucket each, not each from the top of a heap of thousands.
  struct Bucket {
    double time = 0.0;
    std::vector<Entry> entries;
    std::size_t head = 0;  ///< entries before it have been popped
  };
  /// Where a scheduled callback waits. A TimerId names its slot and the slot's generation, so
  /// scheduling, cancelling and running one index an array instead of a hash map (a 1,000-drone
  /// run schedules tens of millions); a slot is reused under the next generation.
  struct Slot {
    std::function<void()> fn;
    std::uint32_t gen = 0;
    bool live = false;
  };
  static std::uint32_t slot_of(TimerId id) { return static_cast<std::uint32_t>(id) - 1; }
  static std::uint32_t gen_of(TimerId id) { return static_cast<std::uint32_t>(id >> 32); }
  bool live(std::uint32_t slot, std::uint32_t gen) const {
    return slot < slots_.size() && slots_[slot].live && slots_[slot].gen == gen;
  }
  /// Takes the callback out of its slot and frees the slot.
  std::function<void()> take(std::uint32_t slot);
  /// Appends to the bucket of time `t`, making one when none is queued.
  void push(double t, Entry e);
  /// A time's hash from its bits, mixed: std::hash<double> runs a byte hash, and the map
  /// computes it again for each node it passes in a bucket (4 % of a verify's flights).
  struct TimeHash {
    std::size_t operator()(double t) const noexcept {
      std::uint64_t bits = t == 0.0 ? 0 : std::bit_cast<std::uint64_t>(t);  // -0.0 == 0.0
      bits *= 0x9E3779B97F4A7C15ull;
      return static_cast<std::size_t>(bits ^ (bits >> 32));
    }
  };
  using TimeBuckets = std::unordered_map<double, std::uint32_t, TimeHash>;
  /// bucket_at_[t] = bucket, in a map node kept from an earlier time when there is one: most
  /// timeouts have an instant of their own, and a node allocated for each is a malloc per timer.
  TimeBuckets::iterator add_time(double t, std::uint32_t bucket);
  void drop_time(double t);  ///< t's bucket left the queue: its node is kept for add_time
  /// The first entry due; the queue must not be empty.
  const Entry& front() const;
  double front_time() const { return buckets_[heap_.front()].time; }
  /// Removes front(); an emptied bucket leaves the heap.
  void pop();
  /// The heap of buckets is a 4-ary min-heap on their times: half the depth of a binary heap,
  /// and a node's children share a cache line.
  void heap_push(std::uint32_t bucket);
  void heap_pop();
  /// Drops cancelled entries once they outnumber the live ones, so a run that schedules and
  /// cancels timeouts for hours holds what is pending, not everything ever cancelled.
  void compact();

  std::size_t run(double limit, bool bounded);
  void start_wall_anchor();
  /// Real time: waits until the wall time of mission time `t`; false when a post() came
  /// first (the caller runs the posted callbacks and looks again).
  bool wait_for(double t);
  /// Moves posted callbacks into the queue at the current mission time.
  void take_posted();
  void run_callback(std::function<void()>& fn) noexcept;
  /// Real time: true (and on_stall's handler run) when the callback due at `t` is late by
  /// more than the stall bound.
  bool stalled_before(double t);
  /// Real time: the mission time the wall clock shows now.
  double wall_mission_time() const;
  void report_error(const std::string& what) noexcept;

  ClockOptions options_;
  double now_ = 0.0;
  std::uint64_t events_run_ = 0;
  bool stop_requested_ = false;
  bool running_ = false;  ///< inside run(): the wall anchor is valid
  /// Cancelled timers stay in their bucket and are skipped when popped: cancel is O(1).
  std::vector<Bucket> buckets_;
  std::vector<std::uint32_t> free_buckets_;
  TimeBuckets bucket_at_;  ///< time → its bucket, while queued
  std::vector<TimeBuckets::node_type> spare_times_;
  std::vector<std::uint32_t> heap_;  ///< the queued buckets, earliest on top
  std::size_t queued_ = 0;           ///< entries in the buckets, cancelled ones included
  std::vector<Slot> slots_;
  std::vector<std::uint32_t> free_slots_;
  std::size_t live_ = 0;
  std::function<void(const std::string&)> on_error_;
  std::mutex post_mutex_;
  std::condition_variable post_cv_;
  std::vector<std::function<void()>> posted_;  ///< guarded by post_mutex_
  /// posted_ is not empty: looked at without the lock before every callback, so a loop that
  /// nothing posts to (a run on virtual time) takes no lock per event.
  std::atomic<bool> has_posted_{false};
  std::optional<double> wall_origin_;
  double wall_anchor_ = 0.0;     ///< real time: wall time at which mission time ...
  double mission_anchor_ = 0.0;  ///< ... was this
  double stall_after_s_ = 0.0;
  std::function<void(double)> on_stall_;
  /// Real time: the wall time the loop last looked at a due callback (or began run()). A
  /// callback is late by the wall time since then or since it was due, whichever is less:
  /// a catch-up of many overdue callbacks in quick succession is not a stall.
  double caught_up_wall_ = 0.0;
  double max_lag_ = 0.0;  ///< see max_lag()
  /// The mission time the last posted callbacks were given: later ones never get an earlier
  /// one, so posted callbacks run in the order they were posted (take_posted).
  double last_posted_at_ = 0.0;
};

}  // namespace eamos::mid
