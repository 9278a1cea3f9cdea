// Drone colours: every picture (graphs, plot, monitor) tells drones apart by colour, so a
// fleet of more than eight must not reuse one (a palette cycling after eight would).
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include "graph/palette.h"

namespace eamos {
namespace {

TEST(Palette, TheFirstEightAreTheOkabeItoColours) {
  EXPECT_EQ(graph::drone_colour(0), "#0072B2");
  EXPECT_EQ(graph::drone_colour(7), "#000000");
  EXPECT_EQ(graph::drone_colour(-1), "#555555");  // no drone (a sync point before cloning)
}

TEST(Palette, FiftyDronesGetFiftyDifferentColours) {
  std::set<std::string> seen;
  for (int d = 0; d < 50; ++d) {
    std::string c = graph::drone_colour(d);
    ASSERT_EQ(c.size(), 7u) << c;
    EXPECT_EQ(c[0], '#');
    EXPECT_TRUE(seen.insert(c).second) << "drone " << d << " repeats " << c;
  }
}

/// Euclidean distance of two "#RRGGBB" colours in RGB (0..255 per channel).
double distance(const std::string& a, const std::string& b) {
  double sum = 0;
  for (int i = 1; i < 7; i += 2) {
    double d = std::stoi(a.substr(i, 2), nullptr, 16) - std::stoi(b.substr(i, 2), nullptr, 16);
    sum += d * d;
  }
  return std::sqrt(sum);
}

TEST(Palette, SixteenDronesAreClearlyApart) {
  for (int a = 0; a < 16; ++a)
    for (int b = a + 1; b < 16; ++b)
      EXPECT_GT(distance(graph::drone_colour(a), graph::drone_colour(b)), 40.0) << a << " and " << b;
}

}  // namespace
}  // namespace eamos
