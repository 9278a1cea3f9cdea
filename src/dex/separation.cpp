#include "dex/separation.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <limits>

namespace eamos::dex {

namespace {

Vec operator-(Vec a, Vec b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec operator+(Vec a, Vec b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec operator*(Vec a, double k) { return {a.x * k, a.y * k, a.z * k}; }
double speed(Vec v) { return std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z); }

/// The times in [0, horizon] at which |p + v t| < r (one dimension or the plane's norm),
/// as [lo, hi]; false when there are none.
bool within(double p0, double p1, double v0, double v1, double r, double horizon, double& lo, double& hi) {
  const double a = v0 * v0 + v1 * v1, b = 2 * (p0 * v0 + p1 * v1), c = p0 * p0 + p1 * p1 - r * r;
  if (a < 1e-12) {
    if (c >= 0) return false;
    lo = 0, hi = horizon;
    return true;
  }
  const double disc = b * b - 4 * a * c;
  if (disc <= 0) return false;
  const double root = std::sqrt(disc);
  lo = std::max(0.0, (-b - root) / (2 * a));
  hi = std::min(horizon, (-b + root) / (2 * a));
  return lo < hi;
}

std::string metres(double m) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f m", m);
  return text;
}

std::string seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f s", s);
  return text;
}

}  // namespace

Prediction predict(Vec pa, Vec va, Vec pb, Vec vb, const fleet::Separation& min, double horizon_s) {
  const Vec dp = pb - pa, dv = vb - va;
  double h_lo, h_hi, v_lo, v_hi;
  if (!within(dp.x, dp.y, dv.x, dv.y, min.horizontal_m, horizon_s, h_lo, h_hi)) return {};
  if (!within(dp.z, 0.0, dv.z, 0.0, min.vertical_m, horizon_s, v_lo, v_hi)) return {};
  const double lo = std::max(h_lo, v_lo), hi = std::min(h_hi, v_hi);
  if (lo >= hi) return {};
  // Already too close: only a pair still closing in is one that holding can help.
  if (lo <= 0.0 && dp.x * dv.x + dp.y * dv.y + dp.z * dv.z >= 0.0) return {};
  return {true, lo};
}

Prediction predict_to_goal(Vec pa, Vec va, double left_m, Vec pb, Vec vb, const fleet::Separation& min,
                           double horizon_s) {
  const double v = speed(va);
  if (!std::isfinite(left_m) || v < 1e-9 || left_m / v >= horizon_s) return predict(pa, va, pb, vb, min, horizon_s);
  const double stop_s = left_m / v;
  if (Prediction moving = predict(pa, va, pb, vb, min, stop_s); moving.conflict) return moving;
  Prediction still = predict(pa + va * stop_s, Vec{}, pb + vb * stop_s, vb, min, horizon_s - stop_s);
  still.in_s += stop_s;
  return still;
}

Vec Course::at(double t) const {
  if (!to_goal) return p + v * t;
  double s = 0.0;
  const double ramp = accel > 0 && cruise > v0 ? (cruise - v0) / accel : 0.0;
  if (t <= ramp)
    s = v0 * t + 0.5 * accel * t * t;
  else
    s = v0 * ramp + 0.5 * accel * ramp * ramp + cruise * (t - ramp);
  return p + u * std::min(s, left);
}

Course goal_course(Vec p, Vec v, Vec goal, const fleet::Limits& limits) {
  Course c{.p = p, .v = v, .to_goal = true};
  const Vec d = goal - p;
  c.left = speed(d);
  if (c.left < 1e-6) return c;  // there already: it stays
  c.u = d * (1.0 / c.left);
  const double across = std::hypot(c.u.x, c.u.y);
  c.cruise = std::numeric_limits<double>::infinity();
  if (across > 1e-9) c.cruise = std::min(c.cruise, limits.max_speed_mps / across);
  if (c.u.z > 1e-9) c.cruise = std::min(c.cruise, limits.max_climb_mps / c.u.z);
  if (c.u.z < -1e-9) c.cruise = std::min(c.cruise, limits.max_descent_mps / -c.u.z);
  c.v0 = std::clamp(v.x * c.u.x + v.y * c.u.y + v.z * c.u.z, 0.0, c.cruise);
  c.accel = limits.max_accel_mps2;
  if (c.accel <= 0) c.v0 = c.cruise;  // no limit given: at full speed at once
  return c;
}

namespace {

/// How far `c` can go from its start within `horizon_s`, at most.
double reach_within(const Course& c, double horizon_s) {
  if (!c.to_goal) return speed(c.v) * horizon_s;
  return std::min(c.left, std::max(c.v0, c.cruise) * horizon_s);
}

}  // namespace

Box Box::of(Vec a, Vec b) { return {std::min(a.x, b.x), std::max(a.x, b.x), std::min(a.y, b.y), std::max(a.y, b.y)}; }

Box Box::with(const Box& o) const {
  return {std::min(x0, o.x0), std::max(x1, o.x1), std::min(y0, o.y0), std::max(y1, o.y1)};
}

Box Box::within(const Box& o) const {
  return {std::max(x0, o.x0), std::min(x1, o.x1), std::max(y0, o.y0), std::min(y1, o.y1)};
}

Box sweep(const Course& c, double horizon_s) { return Box::of(c.at(0.0), c.at(horizon_s)); }

Prediction predict_courses(const Course& a, const Course& b, const fleet::Separation& min, double horizon_s) {
  if (!a.to_goal && !b.to_goal) return predict(a.p, a.v, b.p, b.v, min, horizon_s);
  // Two drones too far apart to close in within the horizon need no step-by-step look: in a
  // fleet most pairs of neighbours are such pairs.
  const double reach = reach_within(a, horizon_s) + reach_within(b, horizon_s);
  const Vec d = b.p - a.p;
  if (std::sqrt(d.x * d.x + d.y * d.y) - reach >= min.horizontal_m || std::abs(d.z) - reach >= min.vertical_m) return {};
  // Each course stays on the line from where it is to where the horizon ends it: two such
  // lines whose boxes lie a minimum apart east-west or north-south (two drones on parallel
  // rows of a show) never come closer.
  Box boxes[2] = {sweep(a, horizon_s), sweep(b, horizon_s)};
  if (boxes[0].apart(boxes[1], min.horizontal_m)) return {};
  Vec pa = a.at(0.0), pb = b.at(0.0);
  for (double t0 = 0.0; t0 < horizon_s; t0 += kCourseStepS) {
    const double t1 = std::min(t0 + kCourseStepS, horizon_s), dt = t1 - t0;
    if (dt <= 1e-9) break;
    const Vec next_a = a.at(t1), next_b = b.at(t1);
    const Vec va = (next_a - pa) * (1.0 / dt), vb = (next_b - pb) * (1.0 / dt);
    if (Prediction p = predict(pa, va, pb, vb, min, dt); p.conflict) return {true, t0 + p.in_s};
    pa = next_a, pb = next_b;
  }
  return {};
}

SeparationGuard::SeparationGuard(const Mission& mission, mid::EventLoop& loop, SeparationHooks hooks)
    : m_(mission),
      loop_(loop),
      hooks_(std::move(hooks)),
      min_(mission.separation),
      tracks_(mission.fleet.size()) {
  // Wide enough that one ring of cells covers two drones at 10 m/s closing in over the
  // horizon; faster drones widen the look-up, not the cells.
  cell_m_ = min_.horizontal_m + 2 * kSeparationHorizonS * 10.0;
}

SeparationGuard::~SeparationGuard() { halt(); }

void SeparationGuard::fly(int d, mid::Drone& drone, const fleet::Limits& limits) {
  tracks_[d].drone = &drone;
  tracks_[d].max_speed = limits.max_speed_mps;
  tracks_[d].limits = limits;
  fastest_seen_ = std::max(fastest_seen_, limits.max_speed_mps);
}

void SeparationGuard::halt() {
  halted_ = true;
  for (Track& k : tracks_) {
    loop_.cancel(k.bound);
    k.bound = mid::kNoTimer;
  }
}

Vec SeparationGuard::now_at(const Track& k) const {
  // Telemetry is a little old when it is read: carried forward along its course.
  const double age = std::clamp(loop_.now() - k.t, 0.0, kSeparationHorizonS);
  return k.p + k.v * age;
}

bool SeparationGuard::outranks(int a, int b) const {
  auto rank = [this](int d) {
    int p = d < static_cast<int>(m_.priorities.size()) ? m_.priorities[d] : 0;
    return p > 0 ? p : d + 1;
  };
  return rank(a) != rank(b) ? rank(a) < rank(b) : a < b;
}

std::optional<Vec> SeparationGuard::goal_of(int d) const {
  const Track& k = tracks_[d];
  if (!k.drone || k.drone->motion_held()) return std::nullopt;
  const std::optional<fleet::Vec3> goal = k.drone->motion_goal();
  if (!goal) return std::nullopt;
  return Vec{goal->x, goal->y, goal->z};
}

Course SeparationGuard::course_of(int d) const {
  const Track& k = tracks_[d];
  const Vec here = now_at(k);
  if (std::optional<Vec> goal = goal_of(d)) return goal_course(here, k.v, *goal, k.limits);
  return Course{.p = here, .v = k.v};
}

bool SeparationGuard::moving(int d) const {
  const Track& k = tracks_[d];
  if (speed(k.v) >= kMovingMps) return true;
  if (!k.drone || k.drone->motion_held()) return false;
  const std::optional<fleet::Vec3> goal = k.drone->motion_goal();
  return goal && speed(Vec{goal->x, goal->y, goal->z} - now_at(k)) > 1e-6;
}

bool SeparationGuard::too_close_to_resume(int h) const {
  const Track& H = tracks_[h];
  if (H.waits_for < 0) return false;
  const Track& W = tracks_[H.waits_for];
  if (!W.airborne) return false;  // landed, or its link lost: no longer kept apart
  const Vec here = now_at(H), there = now_at(W), apart = here - there;
  if (std::hypot(apart.x, apart.y) >= min_.horizontal_m || std::fabs(apart.z) >= min_.vertical_m) return false;
  if (speed(W.v) >= kMovingMps) return true;
  // The other stands: the held drone may leave, but only away from it.
  const std::optional<fleet::Vec3> goal = H.drone->motion_goal();
  if (!goal) return true;
  const Vec way = Vec{goal->x, goal->y, goal->z} - here;
  return way.x * apart.x + way.y * apart.y + way.z * apart.z <= 0.0;
}

bool SeparationGuard::holding(int d) {
  Track& k = tracks_[d];
  if (k.waits_for < 0) return false;
  if (k.drone && k.drone->motion_held()) return true;
  // The held action ended meanwhile (preempted, cancelled, a failsafe): nothing to resume.
  k.waits_for = -1;
  loop_.cancel(k.bound);
  k.bound = mid::kNoTimer;
  return false;
}

namespace {

/// The grid's key of cell (ix, iy), and back: ix in the high 32 bits, iy in the low.
long long cell_key(long long ix, long long iy) { return (ix << 32) ^ (iy & 0xffffffffLL); }
long long cell_x(long long key) { return key >> 32; }
long long cell_y(long long key) { return static_cast<std::int32_t>(key & 0xffffffffLL); }

}  // namespace

long long SeparationGuard::cell_of(const Vec& p) const {
  return cell_key(static_cast<long long>(std::floor(p.x / cell_m_)), static_cast<long long>(std::floor(p.y / cell_m_)));
}

void SeparationGuard::place(int d) {
  Track& k = tracks_[d];
  const long long cell = cell_of(k.p);
  if (k.in_grid && (!k.airborne || cell != k.cell)) {
    std::vector<int>& members = grid_[k.cell];
    members.erase(std::find(members.begin(), members.end(), d));
    if (members.empty()) grid_.erase(k.cell);
    k.in_grid = false;
  }
  if (k.airborne && !k.in_grid) {
    grid_[cell].push_back(d);
    k.cell = cell;
    k.in_grid = true;
  }
}

template <typename Fn>
void SeparationGuard::for_neighbours(int d, double reach_m, Fn fn) {
  const Track& k = tracks_[d];
  const long long rings = std::max(1LL, static_cast<long long>(std::ceil(reach_m / cell_m_)));
  const long long ix = static_cast<long long>(std::floor(k.p.x / cell_m_));
  const long long iy = static_cast<long long>(std::floor(k.p.y / cell_m_));
  // By index, not by copy: giving way and resuming never move a drone between cells (only
  // update() does), so the list stays as it is while `fn` runs.
  auto visit = [&](const std::vector<int>& members) {
    for (std::size_t i = 0; i < members.size(); ++i)
      if (members[i] != d) fn(members[i]);
  };
  // A reach wider than the occupied cells: look through those cells instead of the square.
  if ((2 * rings + 1) * (2 * rings + 1) > static_cast<long long>(grid_.size())) {
    for (const auto& [cell, members] : grid_)
      if (std::llabs(cell_x(cell) - ix) <= rings && std::llabs(cell_y(cell) - iy) <= rings) visit(members);
    return;
  }
  for (long long x = ix - rings; x <= ix + rings; ++x)
    for (long long y = iy - rings; y <= iy + rings; ++y)
      if (auto it = grid_.find(cell_key(x, y)); it != grid_.end()) visit(it->second);
}

void SeparationGuard::update(int d, const mid::DroneState& s) {
  if (d < 0 || d >= static_cast<int>(tracks_.size())) return;
  Track& k = tracks_[d];
  const Vec p{s.x, s.y, s.z};
  // A velocity from samples closer than kMinVelocityDtS apart is mostly their noise (a MAVLink
  // vehicle's two position messages a millisecond apart): the position moves on, the
  // velocity waits for a sample far enough from the one it was measured from.
  if (s.t < k.t) return;  // an older sample overtaken by a newer one
  if (!k.known) {
    k.v = {};
    k.v_p = p, k.v_t = s.t;
  } else if (s.t >= k.v_t + kMinVelocityDtS) {
    k.v = (p - k.v_p) * (1.0 / (s.t - k.v_t));
    k.v_p = p, k.v_t = s.t;
  }
  k.known = true;
  k.p = p;
  k.t = s.t;
  k.airborne = !s.landed && !s.link_lost;
  k.speed_h = std::hypot(k.v.x, k.v.y);
  fastest_seen_ = std::max(fastest_seen_, k.speed_h);
  place(d);
  if (halted_ || !k.airborne || loop_.now() - k.checked_at < kSeparationCheckS) return;
  k.checked_at = loop_.now();
  check(d);
}

void SeparationGuard::check(int d) {
  const Track& k = tracks_[d];
  const bool own = k.drone != nullptr;
  const double reach = min_.horizontal_m + kSeparationHorizonS * (k.speed_h + fastest_seen_);
  if (own && holding(d)) try_resume(d);
  Mine mine;
  for_neighbours(d, reach, [&](int n) {
    // A drone this process flies looks at its own pairs when its own state comes in; a pair
    // with a drone flown elsewhere is looked at from that drone's telemetry too.
    if (own) consider(d, n, &mine);
    if (!tracks_[n].drone) return;
    if (!own) consider(n, d);
    // A held drone stands still and publishes seldom: whoever moves near it looks again.
    if (holding(n)) try_resume(n);
  });
}

// Towards its goal as fast as it may fly (a drone still speeding up is where it will be), and
// as its samples go, ending at its goal (a vehicle slower than its limits is where it is
// going now): the earlier conflict of the two.
Prediction SeparationGuard::foresee(int a, const Course& mine, double left, int b, double horizon_s) const {
  const Track& A = tracks_[a];
  const Track& B = tracks_[b];
  ++foreseen_;
  const Course other = course_of(b);
  Prediction p = predict_courses(mine, other, min_, horizon_s);
  Prediction sampled;
  if (!other.to_goal) {
    sampled = predict_to_goal(now_at(A), A.v, left, now_at(B), B.v, min_, horizon_s);
  } else {
    const double v = speed(A.v);
    Course straight{.p = now_at(A), .v = A.v, .to_goal = v > 1e-9 && std::isfinite(left)};
    if (straight.to_goal) straight.u = A.v * (1.0 / v), straight.v0 = straight.cruise = v, straight.left = left;
    sampled = predict_courses(straight, other, min_, horizon_s);
  }
  if (sampled.conflict && (!p.conflict || sampled.in_s < p.in_s)) p = sampled;
  return p;
}

SeparationGuard::Mine SeparationGuard::mine(int a) const {
  const Track& A = tracks_[a];
  Mine m{.ready = true, .moving = moving(a)};
  if (!m.moving) return m;
  m.course = course_of(a);
  m.left = A.drone->motion_distance_left();
  const Vec here = now_at(A);
  m.box = sweep(m.course, kSeparationHorizonS).with(Box::of(here, here + A.v * kSeparationHorizonS));
  return m;
}

bool SeparationGuard::clear_of(const Box& box, int b) const {
  const Track& B = tracks_[b];
  double speed = B.speed_h;
  if (B.drone) speed = std::isfinite(B.max_speed) ? std::max(speed, B.max_speed) : HUGE_VAL;
  const Vec here = now_at(B);
  const Box reach = Box::around(here, speed * kSeparationHorizonS);
  // Most neighbours of a look are let go here, from the track alone, before their drone is asked.
  if (box.apart(reach, min_.horizontal_m)) return true;
  // Its course (course_of) runs from here towards its goal, stopping there, or straight on
  // along its samples: a drone on its own row of a show stays on that row, although its
  // speed limit alone would let it reach the neighbouring rows.
  const std::optional<Vec> goal = goal_of(b);
  const Box line = goal ? Box::of(here, *goal) : Box::of(here, here + B.v * kSeparationHorizonS);
  return box.apart(reach.within(line), min_.horizontal_m);
}

// From drone a's side (this process flies it): does it give way to b? `mine`, when given, is
// a's side worked out by the first pair of this look that needed it: a cannot change course
// within one look but by giving way, after which it looks at no more pairs.
void SeparationGuard::consider(int a, int b, Mine* given) {
  if (halted_ || holding(a)) return;
  Track& A = tracks_[a];
  const Track& B = tracks_[b];
  if (!A.airborne || !B.airborne) return;
  // A Mine is some 160 bytes: made only for a pair looked at alone, not zeroed for every
  // neighbour of a look that shares one.
  if (!given) {
    Mine local = mine(a);
    return consider_with(a, b, local);
  }
  if (!given->ready) *given = mine(a);
  consider_with(a, b, *given);
}

void SeparationGuard::consider_with(int a, int b, const Mine& m) {
  Track& A = tracks_[a];
  if (!m.moving) return;
  ++pairs_;
  const Prediction p = clear_of(m.box, b) ? Prediction{} : foresee(a, m.course, m.left, b, kSeparationHorizonS);
  if (!p.conflict) {
    if (A.unheld_with == b) A.unheld_with = -1;
    return;
  }
  if (moving(b) && outranks(a, b) && p.in_s > kLastMomentS) return;
  give_way(a, b, p);
}

void SeparationGuard::give_way(int a, int b, const Prediction& p) {
  Track& A = tracks_[a];
  const std::string course = "would come within " + metres(min_.horizontal_m) + " horizontally and " +
                             metres(min_.vertical_m) + " vertically in " + seconds(p.in_s);
  if (!A.drone->hold_motion(0.0)) {
    if (A.unheld_with != b) trace(a, b, "conflict", course + "; its action cannot be held");
    A.unheld_with = b;
    return;
  }
  trace(a, b, "conflict", course);
  A.waits_for = b;
  A.held_since = loop_.now();
  // Its course once it flies on: the way it was going, at full speed (it was perhaps still
  // speeding up), so that it resumes only when the way is clear for the fastest it may fly.
  const double h = std::hypot(A.v.x, A.v.y), full = std::max(A.max_speed, h);
  A.hold_v = A.v;
  A.resume_v = h > 1e-9 ? Vec{A.v.x * full / h, A.v.y * full / h, A.v.z} : A.v;
  A.blocked_by = b;
  trace(a, b, "give_way", "holds for " + m_.fleet[b]);
  const double since = A.held_since;
  A.bound = loop_.after(kMaxGiveWayS, [this, a, since] { too_long(a, since); });
}

void SeparationGuard::try_resume(int h) {
  if (halted_) return;
  Track& H = tracks_[h];
  const Vec here = now_at(H);
  const double left = H.drone->motion_distance_left();  // its course ends at its goal
  const std::optional<fleet::Vec3> goal = H.drone->motion_goal();
  // Held within the minimum of the drone it gave way to: flying on could only keep it there.
  int blocker = too_close_to_resume(h) ? H.waits_for : -1;
  const double reach = min_.horizontal_m + kResumeHorizonS * (std::hypot(H.resume_v.x, H.resume_v.y) + fastest_seen_);
  for_neighbours(h, reach, [&](int n) {
    if (blocker >= 0 || !tracks_[n].airborne) return;
    ++pairs_;
    const Track& N = tracks_[n];
    // It speeds up from a stop: its course at the speed it had when it gave way, and at a
    // quarter, half, three quarters and all of its full speed.
    // Over twice the horizon: a conflict that just slipped past the horizon as it braked
    // would otherwise let it fly on at once and stop again.
    const double horizon = kResumeHorizonS;
    if (predict_to_goal(here, H.hold_v, left, now_at(N), N.v, min_, horizon).conflict) blocker = n;
    for (double share : {0.25, 0.5, 0.75, 1.0})
      if (predict_to_goal(here, H.resume_v * share, left, now_at(N), N.v, min_, horizon).conflict) blocker = n;
    if (blocker >= 0 || !goal) return;
    // Towards its goal, from the speed it has (it may still be braking) speeding up as its
    // limits let it, and at steady shares of its full speed along the line to it (the way it
    // was going may not be the way to its goal).
    const Course theirs = course_of(n);
    Course mine = goal_course(here, H.v, Vec{goal->x, goal->y, goal->z}, H.limits);
    // What consider() will see once it flies on, so that it does not give way again at once.
    if (foresee(h, mine, left, n, horizon).conflict) blocker = n;
    mine.accel = 0.0;
    for (double share : {0.25, 0.5, 0.75, 1.0}) {
      Course steady = mine;
      steady.v0 = steady.cruise = mine.cruise * share;
      if (predict_courses(steady, theirs, min_, horizon).conflict) blocker = n;
    }
  });
  H.blocked_by = blocker;
  if (blocker >= 0) {
    // Two held drones, both stopped, each in the other's way: neither will ever fly on.
    const Track& B = tracks_[blocker];
    if (B.drone && B.blocked_by == h && holding(blocker) && speed(H.v) < kMovingMps && speed(B.v) < kMovingMps &&
        hooks_.on_stuck)
      hooks_.on_stuck(m_.fleet[blocker] + " and " + m_.fleet[h] + " give way to each other " +
                      metres(distance(h, blocker)) + " apart: neither can fly on without losing separation");
    return;
  }
  if (!H.drone->resume_motion()) return;
  const int other = H.waits_for;
  H.waits_for = -1;
  loop_.cancel(H.bound);
  H.bound = mid::kNoTimer;
  trace(h, other, "resume", "held " + seconds(loop_.now() - H.held_since));
}

void SeparationGuard::too_long(int h, double since) {
  Track& H = tracks_[h];
  H.bound = mid::kNoTimer;
  if (halted_ || !holding(h) || H.held_since != since || !hooks_.on_stuck) return;
  hooks_.on_stuck(m_.fleet[h] + " gave way to " + m_.fleet[H.waits_for] + " for " + seconds(kMaxGiveWayS) +
                  " and its course is still not clear (" + metres(distance(h, H.waits_for)) + " apart)");
}

double SeparationGuard::distance(int a, int b) const {
  return speed(now_at(tracks_[a]) - now_at(tracks_[b]));
}

void SeparationGuard::trace(int d, int other, const char* event, const std::string& reason) {
  if (!hooks_.trace) return;
  TraceEvent e;
  e.t = loop_.now();
  e.drone = m_.fleet[d];
  e.event = event;
  e.name = "separation";
  e.other = other >= 0 ? m_.fleet[other] : "";
  e.to = other;
  if (other >= 0) e.distance = std::round(distance(d, other) * 1000.0) / 1000.0;
  e.reason = reason;
  hooks_.trace->record(e);
}

}  // namespace eamos::dex
