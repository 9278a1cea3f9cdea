// The sweep behind verify's pairwise checks (sweep.h). Only a drone that published a sample
// can change how near it is to another, so each step compares the drones that moved with
// the drones around them, and with the drones they were near before (to see them part).
#include "verify/sweep.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace eamos::verify {

namespace {

// Cells a little wider than asked: a pair nearer than the separation then lies in neighbouring
// cells even when the division rounds.
constexpr double kCellMargin = 1.001;

using Step = Timeline::Step;

bool finite(const dex::Sample& s) { return std::isfinite(s.x) && std::isfinite(s.y); }

/// The separation sweep's state: where each drone is and which pairs are near now.
class SeparationSweep {
 public:
  SeparationSweep(const Timeline& flight, const fleet::Separation& sep)
      : tracks_(flight.tracks), steps_(flight.steps), sep_(sep),
        grid_(sep.horizontal_m * kCellMargin, flight.area, static_cast<int>(tracks_.size())), now_(tracks_.size(), nullptr),
        near_(tracks_.size()), moved_at_(tracks_.size(), -1), seen_(tracks_.size(), -1) {}

  std::vector<Approach> run() {
    const std::vector<Step>& steps = steps_;
    std::vector<int> moved;
    for (std::size_t i = 0; i < steps.size();) {
      double t = steps[i].t;
      moved.clear();
      for (; i < steps.size() && steps[i].t == t; ++i) {
        int d = steps[i].drone;
        now_[d] = &(*tracks_[d])[steps[i].index];
        if (moved_at_[d] != step_) moved.push_back(d);
        moved_at_[d] = step_;
      }
      for (int d : moved) {
        if (now_[d]->landed || !finite(*now_[d])) grid_.remove(d);
        else grid_.place(d, now_[d]->x, now_[d]->y);
      }
      for (int d : moved) compare(d, t);
      ++step_;
    }
    std::sort(found_.begin(), found_.end(), [](const Approach& x, const Approach& y) {
      if (x.a != y.a) return x.a < y.a;
      return x.b != y.b ? x.b < y.b : x.t < y.t;
    });
    return std::move(found_);
  }

 private:
  /// Compares `d`, which just moved, with every drone it may be near now or was near before.
  void compare(int d, double t) {
    candidates_.assign(near_[d].begin(), near_[d].end());
    if (!now_[d]->landed && finite(*now_[d])) grid_.around(now_[d]->x, now_[d]->y, candidates_);
    ++token_;
    for (int w : candidates_) {
      if (w == d || seen_[w] == token_) continue;
      seen_[w] = token_;
      if (moved_at_[w] == step_ && w < d) continue;  // compared when w's turn came
      pair(std::min(d, w), std::max(d, w), t);
    }
  }

  void pair(int a, int b, double t) {
    const dex::Sample* pa = now_[a];
    const dex::Sample* pb = now_[b];
    double h = std::hypot(pa->x - pb->x, pa->y - pb->y), v = std::abs(pa->z - pb->z);
    bool now = !pa->landed && !pb->landed && h < sep_.horizontal_m && v < sep_.vertical_m;
    auto& of_a = near_[a];
    auto it = std::find(of_a.begin(), of_a.end(), b);
    bool was = it != of_a.end();
    if (now == was) return;
    auto& of_b = near_[b];
    if (now) {
      of_a.push_back(b);
      of_b.push_back(a);
      found_.push_back({a, b, t, pa, pb, h, v});
      return;
    }
    of_a.erase(it);
    of_b.erase(std::find(of_b.begin(), of_b.end(), a));
  }

  const std::vector<const std::vector<dex::Sample>*>& tracks_;
  const std::vector<Step>& steps_;
  fleet::Separation sep_;
  Grid grid_;
  std::vector<const dex::Sample*> now_;  ///< per drone: its sample in force
  std::vector<std::vector<int>> near_;   ///< per drone: the drones nearer than the separation now
  std::vector<long> moved_at_;           ///< per drone: the last step at which it published
  std::vector<long> seen_;               ///< per drone: the last comparison round that met it
  std::vector<int> candidates_;
  std::vector<Approach> found_;
  long step_ = 0, token_ = 0;
};

}  // namespace

Timeline timeline(std::vector<const std::vector<dex::Sample>*> tracks) {
  Timeline out;
  out.tracks = std::move(tracks);
  std::vector<std::size_t> runs = {0};  // each track is a sorted run: merge them pairwise
  std::size_t samples = 0;
  for (const std::vector<dex::Sample>* track : out.tracks) samples += track->size();
  out.steps.reserve(samples);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Area& area = out.area;
  area = {kInf, kInf, -kInf, -kInf};
  for (std::size_t d = 0; d < out.tracks.size(); ++d) {
    for (std::size_t i = 0; i < out.tracks[d]->size(); ++i) {
      const dex::Sample& s = (*out.tracks[d])[i];
      out.steps.push_back({s.t, static_cast<int>(d), static_cast<int>(i)});
      if (!finite(s)) continue;
      area.x0 = std::min(area.x0, s.x), area.y0 = std::min(area.y0, s.y);
      area.x1 = std::max(area.x1, s.x), area.y1 = std::max(area.y1, s.y);
    }
    runs.push_back(out.steps.size());
  }
  if (!(area.x0 <= area.x1)) area = Area{};  // no finite position
  // std::merge takes the first run's element on a tie: the lower-numbered drone comes first.
  auto earlier = [](const Step& a, const Step& b) { return a.t < b.t; };
  std::vector<Step> other(out.steps.size());
  while (runs.size() > 2) {
    std::vector<std::size_t> merged_runs = {0};
    for (std::size_t r = 0; r + 1 < runs.size(); r += 2) {
      std::size_t mid = runs[r + 1], end = r + 2 < runs.size() ? runs[r + 2] : mid;
      std::merge(out.steps.begin() + runs[r], out.steps.begin() + mid, out.steps.begin() + mid,
                 out.steps.begin() + end, other.begin() + runs[r], earlier);
      merged_runs.push_back(end);
    }
    out.steps.swap(other);
    runs = std::move(merged_runs);
  }
  return out;
}

Grid::Grid(double cell, const Area& area, int drones)
    : cell_(cell), area_(area), next_(drones, -1), prev_(drones, -1), where_(drones, -1) {
  auto cells_across = [this](double extent) {
    double n = std::floor(extent / cell_) + 1;
    return std::isfinite(n) ? n : 1.0;  // an extent past the doubles' range: one column
  };
  double width = area.x1 - area.x0, height = area.y1 - area.y0;
  while (cells_across(width) * cells_across(height) > kMaxCells) cell_ *= 2;
  columns_ = static_cast<int>(cells_across(width));
  rows_ = static_cast<int>(cells_across(height));
  first_.assign(static_cast<std::size_t>(columns_) * rows_, -1);
}

int Grid::index(double offset, int count) const {
  double i = std::floor(offset / cell_);
  if (i >= count) return count - 1;
  return i >= 0 ? static_cast<int>(i) : 0;  // below the area, or not a number (inf / inf)
}

void Grid::remove(int drone) {
  int cell = where_[drone];
  if (cell < 0) return;
  if (prev_[drone] >= 0) next_[prev_[drone]] = next_[drone];
  else first_[cell] = next_[drone];
  if (next_[drone] >= 0) prev_[next_[drone]] = prev_[drone];
  where_[drone] = -1;
}

void Grid::place(int drone, double x, double y) {
  if (!std::isfinite(x) || !std::isfinite(y)) {
    remove(drone);
    return;
  }
  int cell = index(y - area_.y0, rows_) * columns_ + index(x - area_.x0, columns_);
  if (where_[drone] == cell) return;
  remove(drone);
  prev_[drone] = -1;
  next_[drone] = first_[cell];
  if (first_[cell] >= 0) prev_[first_[cell]] = drone;
  first_[cell] = drone;
  where_[drone] = cell;
}

void Grid::around(double x, double y, std::vector<int>& out) const {
  if (!std::isfinite(x) || !std::isfinite(y)) return;
  int cx = index(x - area_.x0, columns_), cy = index(y - area_.y0, rows_);
  for (int r = std::max(cy - 1, 0); r <= std::min(cy + 1, rows_ - 1); ++r)
    for (int c = std::max(cx - 1, 0); c <= std::min(cx + 1, columns_ - 1); ++c)
      for (int d = first_[static_cast<std::size_t>(r) * columns_ + c]; d >= 0; d = next_[d]) out.push_back(d);
}

std::vector<Approach> approaches(const Timeline& flight, const fleet::Separation& separation) {
  // Nothing is nearer than a separation of zero (or not a number).
  if (!(separation.horizontal_m > 0) || !(separation.vertical_m > 0)) return {};
  return SeparationSweep(flight, separation).run();
}

std::vector<int> standing_near(const Timeline& flight, const std::vector<SpotQuery>& queries, double radius) {
  const auto& tracks = flight.tracks;
  const std::vector<Step>& steps = flight.steps;
  std::vector<int> out(queries.size(), -1);
  if (!(radius > 0)) return out;
  std::vector<std::size_t> order(queries.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return queries[a].t < queries[b].t; });
  std::vector<const dex::Sample*> now(tracks.size(), nullptr);
  Grid grounded(radius * kCellMargin, flight.area, static_cast<int>(tracks.size()));
  std::vector<int> around;
  std::size_t next = 0;
  for (std::size_t q : order) {
    const SpotQuery& query = queries[q];
    for (; next < steps.size() && steps[next].t <= query.t; ++next) {
      int d = steps[next].drone;
      now[d] = &(*tracks[d])[steps[next].index];
      if (now[d]->landed) grounded.place(d, now[d]->x, now[d]->y);
      else grounded.remove(d);
    }
    around.clear();
    grounded.around(query.x, query.y, around);
    for (int o : around)
      if (o != query.drone && std::hypot(now[o]->x - query.x, now[o]->y - query.y) < radius &&
          (out[q] < 0 || o < out[q]))
        out[q] = o;
  }
  return out;
}

}  // namespace eamos::verify
