// The picture of a run (`eamos run --plot`): a tiny two-drone mission flown in the
// simulator, drawn, and checked for its parts.
#include <gtest/gtest.h>

#include <string>

#include "dex/plot.h"
#include "flight.h"

namespace eamos {
namespace {

int count(const std::string& s, const std::string& what) {
  int n = 0;
  for (std::size_t i = s.find(what); i != std::string::npos; i = s.find(what, i + what.size())) ++n;
  return n;
}

TEST(Plot, DrawsTracksAndOneBarPerAction) {
  const char* text =
      "var A Quad\nvar B Quad\n"
      "func INIT() { PAR_go(); PAR_down() }\n"
      "func PAR_go() { SEQ_a(); SEQ_b() }\n"
      "func SEQ_a() { A.Arm(); A.Takeoff(3); A.FlyByX(4); A.Land() }\n"
      "func SEQ_b() { B.Arm(); B.Takeoff(5); B.Land() }\n"
      "func PAR_down() { A.Disarm(); B.Disarm() }\n";
  test::Flight f = test::fly(text);
  const dex::RunResult& result = f.result;
  ASSERT_TRUE(result.completed) << result.error;

  // Samples: the state before start, then only changes; A flew, so it has many.
  ASSERT_EQ(result.drones.size(), 2u);
  EXPECT_GT(result.drones[0].track.size(), 10u);
  EXPECT_FALSE(result.drones[0].track.front().armed);
  EXPECT_TRUE(result.drones[0].track.back().landed);
  for (std::size_t i = 1; i < result.drones[0].track.size(); ++i)
    EXPECT_LE(result.drones[0].track[i - 1].t, result.drones[0].track[i].t);

  std::string svg = dex::plot_svg(result, f.events);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  while (!svg.empty() && svg.back() == '\n') svg.pop_back();
  EXPECT_TRUE(svg.ends_with("</svg>"));
  EXPECT_EQ(count(svg, "<"), count(svg, ">")) << "every tag closed; text escaped";
  EXPECT_NE(svg.find(">A</text>"), std::string::npos);
  EXPECT_NE(svg.find(">B</text>"), std::string::npos);
  int starts = 0;
  for (const auto& e : f.events) starts += e.event == "start";
  EXPECT_EQ(starts, 9);
  EXPECT_EQ(count(svg, "data-action="), starts);
  EXPECT_EQ(count(svg, "data-outcome=\"succeeded\""), starts);
  // A's flight is one polyline in the air with more than two points.
  std::size_t air = svg.find("class=\"air\" points=\"");
  ASSERT_NE(air, std::string::npos);
  std::size_t from = air + 20, to = svg.find('"', from);
  EXPECT_GT(count(svg.substr(from, to - from), ","), 2);
}

}  // namespace
}  // namespace eamos
