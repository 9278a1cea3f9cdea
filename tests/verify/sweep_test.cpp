// verify's pairwise checks through the grid sweep (src/verify/sweep.h): the same approaches
// and occupied spots as comparing every pair of drones at every sample time of either, which
// is what `everyPair` and `everyDrone` below do, the way verify did before the grid.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "verify/sweep.h"

namespace eamos::verify {
namespace {

using Track = std::vector<dex::Sample>;

dex::Sample at(double t, double x, double y, double z, bool landed = false) {
  return dex::Sample{t, x, y, z, true, landed, 100.0};
}

Timeline timelineOf(const std::vector<Track>& tracks) {
  std::vector<const Track*> out;
  for (const Track& t : tracks) out.push_back(&t);
  return timeline(std::move(out));
}

const dex::Sample* sample_at(const Track& track, double t) {
  auto it = std::upper_bound(track.begin(), track.end(), t, [](double v, const dex::Sample& s) { return v < s.t; });
  return it == track.begin() ? nullptr : &*(it - 1);
}

/// Every pair, at every sample time of either drone.
std::vector<std::tuple<int, int, double>> everyPair(const std::vector<Track>& tracks, const fleet::Separation& sep) {
  std::vector<std::tuple<int, int, double>> out;
  for (std::size_t a = 0; a < tracks.size(); ++a)
    for (std::size_t b = a + 1; b < tracks.size(); ++b) {
      std::vector<double> times;
      for (const auto& s : tracks[a]) times.push_back(s.t);
      for (const auto& s : tracks[b]) times.push_back(s.t);
      std::sort(times.begin(), times.end());
      bool close = false;
      for (double t : times) {
        const dex::Sample* pa = sample_at(tracks[a], t);
        const dex::Sample* pb = sample_at(tracks[b], t);
        if (!pa || !pb) continue;
        bool now = !pa->landed && !pb->landed && std::hypot(pa->x - pb->x, pa->y - pb->y) < sep.horizontal_m &&
                   std::abs(pa->z - pb->z) < sep.vertical_m;
        if (now && !close) out.emplace_back(static_cast<int>(a), static_cast<int>(b), t);
        close = now;
      }
    }
  return out;
}

std::vector<std::tuple<int, int, double>> withTheGrid(const std::vector<Track>& tracks, const fleet::Separation& sep) {
  std::vector<std::tuple<int, int, double>> out;
  for (const Approach& a : approaches(timelineOf(tracks), sep)) out.emplace_back(a.a, a.b, a.t);
  return out;
}

/// 100 drones on a line 5 m apart, each flying 20 m east at 5 m over 10 s (20 samples a
/// second); `swap` and `swap + 1` fly towards each other's line instead and meet half way.
std::vector<Track> hundredInALine(int swap) {
  std::vector<Track> tracks(100);
  for (int d = 0; d < 100; ++d) {
    double y0 = 5.0 * d;
    double y1 = d == swap ? y0 + 5.0 : d == swap + 1 ? y0 - 5.0 : y0;
    tracks[d].push_back(at(0.0, 0.0, y0, 0.0, true));
    for (int k = 1; k <= 200; ++k) {
      double s = k / 200.0;
      tracks[d].push_back(at(k * 0.05, 20.0 * s, y0 + (y1 - y0) * s, 5.0));
    }
  }
  return tracks;
}

TEST(SeparationSweep, AViolationBetweenTwoOfAHundredDronesIsFoundWithTheGrid) {
  fleet::Separation sep;  // 2 m horizontally, 1 m vertically
  std::vector<Track> tracks = hundredInALine(41);
  std::vector<Approach> found = approaches(timelineOf(tracks), sep);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].a, 41);
  EXPECT_EQ(found[0].b, 42);
  // They close at 1 m/s from 5 m apart: 2 m apart at 3 s, nearer at the next sample.
  EXPECT_NEAR(found[0].t, 3.05, 1e-9);
  EXPECT_LT(found[0].horizontal, 2.0);
  EXPECT_EQ(found[0].pa, sample_at(tracks[41], found[0].t));
  EXPECT_EQ(found[0].pb, sample_at(tracks[42], found[0].t));
  EXPECT_EQ(withTheGrid(tracks, sep), everyPair(tracks, sep));
}

// x = 0 and y = 0 are cell boundaries whatever the cell's width: drones either side of them,
// side by side and across the corner, are still compared.
TEST(SeparationSweep, DronesEitherSideOfACellBoundaryAreStillNear) {
  fleet::Separation sep;
  std::vector<Track> tracks = {
      {at(0.0, -0.3, 10.0, 5.0)}, {at(0.0, 0.3, 10.0, 5.0)},      // across x = 0
      {at(0.0, -0.7, -0.7, 5.0)}, {at(0.1, 0.7, 0.7, 5.0)},       // across the corner, 1.98 m apart
      {at(0.0, 40.0, -1.0, 5.0)}, {at(0.0, 42.5, -1.0, 5.0)},     // 2.5 m apart: not near
  };
  std::vector<std::tuple<int, int, double>> expected = {{0, 1, 0.0}, {2, 3, 0.1}};
  EXPECT_EQ(withTheGrid(tracks, sep), expected);
  EXPECT_EQ(everyPair(tracks, sep), expected);
}

// A pair that parts (one flies cells away, or lands) and meets again is reported again.
TEST(SeparationSweep, APairThatPartsAndMeetsAgainIsReportedTwice) {
  fleet::Separation sep;
  Track still = {at(0.0, 0.0, 0.0, 5.0)};
  Track away_and_back = {at(0.0, 1.0, 0.0, 5.0), at(1.0, 50.0, 0.0, 5.0), at(2.0, 1.0, 0.0, 5.0),
                         at(3.0, 1.0, 0.0, 0.0, true), at(4.0, 1.0, 0.0, 0.5)};
  std::vector<Track> tracks = {still, away_and_back};
  std::vector<std::tuple<int, int, double>> expected = {{0, 1, 0.0}, {0, 1, 2.0}};
  EXPECT_EQ(withTheGrid(tracks, sep), expected);  // at 4 s it is 4.5 m below: apart
  EXPECT_EQ(everyPair(tracks, sep), expected);
}

// 60 drones wandering over a 40 m square for half a minute, taking off and landing: the grid
// finds every approach comparing every pair finds, in the same order.
TEST(SeparationSweep, TheGridFindsWhatComparingEveryPairFinds) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> step(-1.5, 1.5), place(0.0, 40.0), chance(0.0, 1.0);
  std::vector<Track> tracks(60);
  for (int d = 0; d < 60; ++d) {
    double x = place(random), y = place(random), z = 0.0;
    double t = 0.013 * d;  // the drones publish at their own moments
    for (int k = 0; k < 300; ++k, t += 0.1) {
      bool landed = z <= 0.0 && chance(random) < 0.9;
      z = landed ? 0.0 : std::clamp(z + step(random), 0.0, 6.0);
      x += step(random), y += step(random);
      tracks[d].push_back(at(t, x, y, z, landed));
    }
  }
  for (fleet::Separation sep : {fleet::Separation{}, fleet::Separation{5.0, 2.0}, fleet::Separation{0.5, 10.0}}) {
    std::vector<std::tuple<int, int, double>> expected = everyPair(tracks, sep);
    EXPECT_GT(expected.size(), 10u) << "the wandering should bring drones together";
    EXPECT_EQ(withTheGrid(tracks, sep), expected) << sep.horizontal_m << " m";
  }
}

// A drone 1,000 km from the rest would need more cells than the grid keeps: the cells widen,
// and the approaches stay those comparing every pair finds, out there as well as at home.
TEST(SeparationSweep, DronesFarFromTheRestWidenTheCellsAndNothingIsMissed) {
  fleet::Separation sep;
  std::vector<Track> tracks = hundredInALine(41);
  tracks.push_back({at(0.0, 1e6, 0.0, 5.0), at(1.0, 1e6, 3.0, 5.0)});
  tracks.push_back({at(0.0, 1e6 + 1.0, 0.5, 5.0)});
  Area area = timelineOf(tracks).area;
  ASSERT_GT((area.x1 - area.x0) / (sep.horizontal_m * 1.001) * (area.y1 - area.y0) / (sep.horizontal_m * 1.001),
            Grid::kMaxCells);
  std::vector<std::tuple<int, int, double>> expected = {{41, 42, 3.05}, {100, 101, 0.0}};
  std::vector<std::tuple<int, int, double>> found = withTheGrid(tracks, sep);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(std::get<0>(found[0]), 41);
  EXPECT_NEAR(std::get<2>(found[0]), 3.05, 1e-9);
  EXPECT_EQ(found[1], (std::tuple<int, int, double>{100, 101, 0.0}));
  EXPECT_EQ(found, everyPair(tracks, sep));
}

// Positions and queries outside the area the grid was made for count at its edge.
TEST(Grid, APositionOutsideItsAreaIsFoundFromNearby) {
  Grid grid(2.0, Area{0.0, 0.0, 10.0, 10.0}, 3);
  grid.place(0, -50.0, 5.0);
  grid.place(1, 5.0, 5.0);
  grid.place(2, std::nan(""), 5.0);  // nowhere: near no one
  std::vector<int> out;
  grid.around(-49.0, 5.0, out);
  EXPECT_EQ(out, std::vector<int>{0});
  out.clear();
  grid.around(5.0, 5.0, out);
  EXPECT_EQ(out, std::vector<int>{1});
  grid.place(1, 1e300, -1e300);
  out.clear();
  grid.around(20.0, -3.0, out);
  EXPECT_EQ(out, std::vector<int>{1});
  grid.remove(1);
  out.clear();
  grid.around(20.0, -3.0, out);
  EXPECT_TRUE(out.empty());
}

TEST(SpotSweep, FindsTheLowestNumberedDroneStandingNearATakeoffOrLanding) {
  std::vector<Track> tracks = {
      {at(0.0, -0.5, 0.0, 0.0, true)},                              // stands just across x = 0
      {at(0.0, 0.5, 0.0, 0.0, true), at(5.0, 0.5, 0.0, 3.0)},       // takes off at 5 s
      {at(0.0, 0.9, 0.4, 0.0, true)},
      {at(0.0, 30.0, 0.0, 0.0, true)},
  };
  std::vector<SpotQuery> queries = {
      {1, 0.0, 0.5, 0.0},   // drone 1 taking off: drone 0 is 1 m away, drone 2 too
      {3, 1.0, 0.0, 0.0},   // a query for drone 3 at the origin: drone 0 is nearest-numbered
      {2, 6.0, 0.9, 0.4},   // drone 2 at 6 s: drone 1 flew off, drone 0 is 1.45 m away
      {0, 6.0, -5.0, 0.0},  // nobody within 2 m
      {3, 6.0, 30.0, 1.0},  // itself does not count
  };
  EXPECT_EQ(standing_near(timelineOf(tracks), queries, 2.0), (std::vector<int>{0, 0, 0, -1, -1}));
  EXPECT_EQ(standing_near(timelineOf(tracks), {{0, 6.0, -0.5, 0.0}}, 1.0), (std::vector<int>{-1}));
  EXPECT_EQ(standing_near(timelineOf(tracks), {{0, 0.0, -0.5, 0.0}}, 1.0), (std::vector<int>{-1}))
      << "drone 1 stands exactly 1 m away: not nearer than 1 m";
  EXPECT_EQ(standing_near(timelineOf(tracks), {{0, 0.0, -0.5, 0.0}}, 1.01), (std::vector<int>{1}));
}

}  // namespace
}  // namespace eamos::verify
