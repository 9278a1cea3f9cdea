#include "graph/palette.h"

#include <cmath>
#include <cstdio>

namespace eamos::graph {

namespace {
/// HSV (h in degrees, s and v in 0..1) as "#RRGGBB".
std::string hsv(double h, double s, double v) {
  double c = v * s, hp = std::fmod(h, 360.0) / 60.0, x = c * (1 - std::fabs(std::fmod(hp, 2.0) - 1));
  double r = 0, g = 0, b = 0;
  if (hp < 1) r = c, g = x;
  else if (hp < 2) r = x, g = c;
  else if (hp < 3) g = c, b = x;
  else if (hp < 4) g = x, b = c;
  else if (hp < 5) r = x, b = c;
  else r = c, b = x;
  double m = v - c;
  char out[8];
  std::snprintf(out, sizeof out, "#%02X%02X%02X", static_cast<int>(std::lround((r + m) * 255)),
                static_cast<int>(std::lround((g + m) * 255)), static_cast<int>(std::lround((b + m) * 255)));
  return out;
}
}  // namespace

std::string drone_colour(int d) {
  static const char* okabe_ito[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                    "#E69F00", "#56B4E9", "#F0E442", "#000000"};
  if (d < 0) return "#555555";
  if (d < 8) return okabe_ito[d];
  // Golden-angle hues never repeat; alternating darkness keeps neighbours apart too, and
  // both stay dark enough for text on white.
  int k = d - 8;
  return hsv(20.0 + k * 137.508, 0.75, k % 2 == 0 ? 0.62 : 0.45);
}

std::vector<std::string> drone_palette(int count) {
  std::vector<std::string> colours;
  for (int d = 0; d < count; ++d) colours.push_back(drone_colour(d));
  return colours;
}

}  // namespace eamos::graph
