#pragma once
// Separation kept in flight (docs/faults.md, "Separation in flight"): each DEX reads the
// positions of the drones near its own (their telemetry), predicts every pair's straight
// courses over a short horizon and, where two would come closer than the fleet's
// min_separation (horizontally and vertically at once), makes one of them give way: it
// holds its goal-directed motion where it can stop (the Uniform Space's hold_motion, on the
// simulator and on MAVLink alike) and flies on once its own course is clear again. A hold
// that cannot clear (two held drones each in the other's course, or longer than kMaxGiveWayS) fails
// the mission, so the failsafe takes over before anyone collides.
//
// Who gives way, per pair, decided the same way by every DEX from the same telemetry:
//  - a drone that stands still cannot help by holding: the one moving gives way to it;
//  - of two moving drones, the one of lower priority (Mission::priorities, else the later
//    declared) gives way;
//  - one that would lose separation within kLastMomentS gives way whatever its priority:
//    the other may be unable to hold (an Orbit, a Takeoff the autopilot flies) or late.
//
// "Near" is a grid of cells over the horizontal plane: a drone's pairs are looked up in
// the cells its reach spans, so a fleet of a thousand drones in one process costs each
// drone the few drones around it, not the whole fleet.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "dex/mission.h"
#include "dex/trace.h"
#include "mid/drone_api.h"
#include "mid/event_loop.h"

namespace eamos::dex {

inline constexpr double kSeparationHorizonS = 3.0;  ///< how far ahead courses are predicted
inline constexpr double kResumeHorizonS = 6.0;     ///< a held drone's course must be clear this far ahead
inline constexpr double kSeparationCheckS = 0.2;    ///< a drone's pairs are looked at at most this often
inline constexpr double kMaxGiveWayS = 30.0;        ///< a longer hold fails the mission
inline constexpr double kLastMomentS = 1.5;         ///< this close to a loss, priority no longer counts
inline constexpr double kMovingMps = 0.3;           ///< slower counts as standing still
inline constexpr double kMinVelocityDtS = 0.02;     ///< a velocity spans at least this much mission time

struct Vec {
  double x = 0, y = 0, z = 0;
};

/// Where two straight courses (positions and velocities now) lose separation within
/// `horizon_s`: `conflict` and the seconds until it (`in_s`, 0 when already too close and
/// still closing in). Two drones already too close that do not close in are not a conflict:
/// holding either would not part them.
struct Prediction {
  bool conflict = false;
  double in_s = 0.0;
};
Prediction predict(Vec pa, Vec va, Vec pb, Vec vb, const fleet::Separation& min, double horizon_s);
/// As predict(), with a's course ending at its goal `left_m` ahead (a stops there; NaN: no
/// goal known, the course runs on): a drone that flies towards another and stops short of it
/// is no conflict.
Prediction predict_to_goal(Vec pa, Vec va, double left_m, Vec pb, Vec vb, const fleet::Separation& min,
                           double horizon_s);

/// A drone's course over the horizon. Towards a goal (`to_goal`): from `p` along the unit
/// line `u`, speeding up at `accel` from `v0` to `cruise` and stopping `left` ahead, at the
/// goal; a drone still standing with a goal ahead is predicted to move. Without one: straight
/// on from `p` at `v`, the velocity of its last two positions.
struct Course {
  Vec p, v;
  bool to_goal = false;
  Vec u;
  double v0 = 0.0, cruise = 0.0, accel = 0.0, left = 0.0;
  Vec at(double t) const;
};
/// The course of a drone at `p` (velocity `v`) flying to `goal` as fast as `limits` let it:
/// its horizontal, climb and descent speeds, reached at max_accel.
Course goal_course(Vec p, Vec v, Vec goal, const fleet::Limits& limits);
inline constexpr double kApartMarginM = 1e-3;  ///< how clearly apart Box::apart wants two boxes
/// The smallest box, east-west and north-south, holding a stretch of course.
struct Box {
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  static Box of(Vec a, Vec b);
  static Box around(Vec c, double r) { return {c.x - r, c.x + r, c.y - r, c.y + r}; }  ///< c ± r east and north
  Box with(const Box& o) const;  ///< both
  Box within(const Box& o) const;  ///< what lies in both (two boxes holding the same course)
  /// Whether every point of one is at least `horizontal_m` (and a margin) east, west, north or
  /// south of every point of the other: no two points of them come within horizontal_m.
  /// The margin keeps a pair whose rounding could put it on the boundary: only pairs clearly
  /// apart are let go, so no prediction differs from a full look. Inline: it runs for every
  /// neighbour of every look.
  bool apart(const Box& o, double horizontal_m) const {
    const double h = horizontal_m + kApartMarginM;
    return o.x0 - x1 >= h || x0 - o.x1 >= h || o.y0 - y1 >= h || y0 - o.y1 >= h;
  }
};
/// Where `c` goes within `horizon_s`: every position on it lies on the line between these.
Box sweep(const Course& c, double horizon_s);
/// As predict(), for courses that need not be straight: each kCourseStepS of the horizon is
/// taken as a straight piece.
Prediction predict_courses(const Course& a, const Course& b, const fleet::Separation& min, double horizon_s);
inline constexpr double kCourseStepS = 0.25;

struct SeparationHooks {
  TraceSink* trace = nullptr;
  /// A give-way that cannot clear: abandon the mission with this reason (failsafe first).
  std::function<void(const std::string&)> on_stuck;
};

class SeparationGuard {
 public:
  /// `mission`: any drone's mission of the run (the fleet, its separation and priorities).
  SeparationGuard(const Mission& mission, mid::EventLoop& loop, SeparationHooks hooks);
  ~SeparationGuard();
  SeparationGuard(const SeparationGuard&) = delete;
  SeparationGuard& operator=(const SeparationGuard&) = delete;

  /// Drone `d` is flown by this process (in one process: every drone; a DEX: its own).
  void fly(int d, mid::Drone& drone, const fleet::Limits& limits);
  /// Drone `d`'s newest state: its own broker's or its telemetry.
  void update(int d, const mid::DroneState& s);
  /// The mission is over: no more give-ways, nothing resumed (the failsafe flies now).
  void halt();

  /// Pairs predicted so far: what the grid saves (tests).
  std::uint64_t pairs_predicted() const { return pairs_; }
  /// Of those, pairs whose courses were worked out: the rest were too far apart for that.
  std::uint64_t pairs_foreseen() const { return foreseen_; }

 private:
  struct Track {
    // What every look reads of each neighbour comes first, in one or two cache lines: a look
    // at a thousand-drone show visits some thirty neighbours.
    bool known = false;
    bool airborne = false;
    int waits_for = -1;      ///< giving way to this drone; -1 none
    double t = 0.0;
    Vec p, v;
    double speed_h = 0.0;  ///< m/s, horizontally: |v|
    mid::Drone* drone = nullptr;  ///< set for the drones this process flies
    double max_speed = 0.0;  ///< m/s, horizontally: its limits
    Vec v_p;          ///< the position and time the velocity was last measured from
    double v_t = 0.0;
    long long cell = 0;
    bool in_grid = false;
    double checked_at = -1e300;
    // drones this process flies
    fleet::Limits limits;
    int unheld_with = -1;    ///< a conflict it could not hold for, recorded once
    int blocked_by = -1;     ///< held: the drone its course was last found blocked by
    double held_since = 0.0;
    Vec hold_v;              ///< its velocity when it gave way
    Vec resume_v;            ///< the same way at full speed: its course once it resumes
    mid::TimerId bound = mid::kNoTimer;
  };

  Vec now_at(const Track& k) const;
  bool outranks(int a, int b) const;
  /// Where drone `d` flies now: towards its goal when this process flies it and it has one
  /// (and is not held), else straight on from its samples.
  Course course_of(int d) const;
  /// Whether drone `d` moves or is about to (a goal it is not held from).
  bool moving(int d) const;
  /// A held drone inside the minimum of the drone it gave way to stays held, unless that one
  /// stands still and its own course leads away from it.
  bool too_close_to_resume(int h) const;
  bool holding(int d);
  long long cell_of(const Vec& p) const;
  void place(int d);
  template <typename Fn>
  void for_neighbours(int d, double reach_m, Fn fn);
  void check(int d);
  /// Drone a's side of its pairs, the same for every neighbour of one look (check): whether
  /// it moves, its course, the distance left to its goal, and the box both of its predicted
  /// courses (towards its goal, and along its samples) stay in over the horizon.
  struct Mine {
    bool ready = false;
    bool moving = false;
    Course course;
    double left = 0.0;
    Box box;
  };
  Mine mine(int a) const;
  /// Whether drone b stays the minimum (and a margin) away from `box` on any course foresee()
  /// predicts for it: it stays within a box around it as wide as it flies at most (its
  /// samples' speed, or its speed limit when it has a goal), and on the line of its course
  /// (to its goal, or straight on along its samples).
  bool clear_of(const Box& box, int b) const;
  /// The goal drone `d` flies to when this process flies it, has one and is not held.
  std::optional<Vec> goal_of(int d) const;
  Prediction foresee(int a, const Course& mine, double left, int b, double horizon_s) const;
  void consider(int a, int b, Mine* mine = nullptr);
  void consider_with(int a, int b, const Mine& mine);  ///< consider() once a's side is known
  void give_way(int a, int b, const Prediction& p);
  void try_resume(int h);
  void too_long(int h, double since);
  double distance(int a, int b) const;
  void trace(int d, int other, const char* event, const std::string& reason);

  const Mission& m_;
  mid::EventLoop& loop_;
  SeparationHooks hooks_;
  fleet::Separation min_;
  double cell_m_;
  double fastest_seen_ = 0.0;  ///< m/s, any drone so far: how far a neighbour can reach
  std::vector<Track> tracks_;
  std::unordered_map<long long, std::vector<int>> grid_;
  bool halted_ = false;
  std::uint64_t pairs_ = 0;
  mutable std::uint64_t foreseen_ = 0;
};

}  // namespace eamos::dex
