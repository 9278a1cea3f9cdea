// The picture of a run (`eamos run --plot`): a tiny two-drone mission flown in the
// simulator, drawn, and checked for its parts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "trace/plot.h"
#include "dex/flight.h"

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

  std::string svg = trace::plot_svg(result, f.events);
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

/// Every `attr="…"` value in `svg` of elements whose opening tag contains `marker`.
std::vector<std::string> attrs(const std::string& svg, const std::string& marker, const std::string& attr) {
  std::vector<std::string> out;
  for (std::size_t i = svg.find(marker); i != std::string::npos; i = svg.find(marker, i + 1)) {
    std::size_t open = svg.rfind('<', i), close = svg.find('>', i);
    std::string tag = svg.substr(open, close - open);
    std::size_t a = tag.find(" " + attr + "=\"");
    if (a == std::string::npos) continue;
    a += attr.size() + 3;
    out.push_back(tag.substr(a, tag.find('"', a) - a));
  }
  return out;
}

// B waits for A's WaitUntil; A decides two conditions at the same instant.
const char* kWaitMission =
    "var A Quad\nvar B Quad\n"
    "func INIT() { PAR_go(); PAR_down() }\n"
    "func PAR_go() { SEQ_a(); SEQ_b() }\n"
    "func SEQ_a() { A.Arm(); If(A.Sensor1() > 1000, SEQ_up, SEQ_up); A.Land() }\n"
    "func SEQ_up() { A.Takeoff(3); A.FlyByX(5) }\n"
    "func SEQ_b() { B.Arm(); WaitUntil(A.X() >= 4.5, SEQ_bgo) }\n"
    "func SEQ_bgo() { B.Takeoff(4); B.Land() }\n"
    "func PAR_down() { A.Disarm(); B.Disarm() }\n";

TEST(Plot, DrawsEveryDronesAltitudeOverTime) {
  test::Flight f = test::fly(kWaitMission);
  ASSERT_TRUE(f.result.completed) << f.result.error;
  std::string svg = trace::plot_svg(f.result, f.events);
  EXPECT_EQ(attrs(svg, "class=\"altitude\"", "data-drone"), (std::vector<std::string>{"A", "B"}));
  EXPECT_NE(svg.find(">Altitude over time</text>"), std::string::npos);
  EXPECT_NE(svg.find(">z (m, up)</text>"), std::string::npos);
}

TEST(Plot, DrawsWhoWaitedOnWhomAndHowLong) {
  test::Flight f = test::fly(kWaitMission);
  ASSERT_TRUE(f.result.completed) << f.result.error;
  std::string svg = trace::plot_svg(f.result, f.events);
  // B armed at 0 and took off when A's WaitUntil came true: it waited that long on A.
  double go = f.time_of("start", "B.Takeoff(4)");
  ASSERT_GT(go, 1.0);
  std::vector<std::string> on = attrs(svg, "class=\"wait\"", "data-on");
  std::vector<std::string> who = attrs(svg, "class=\"wait\"", "data-drone");
  std::vector<std::string> seconds = attrs(svg, "class=\"wait\"", "data-seconds");
  ASSERT_FALSE(on.empty()) << svg;
  EXPECT_EQ(who[0], "B");
  EXPECT_EQ(on[0], "A");
  EXPECT_NEAR(std::stod(seconds[0]), go, 0.01);
  EXPECT_NE(svg.find("waits " + seconds[0] + " s on A"), std::string::npos);
  EXPECT_GE(count(svg, "class=\"trigger\""), 1);  // the arrow from A's row
}

TEST(Plot, LabelsConditionMarksWithoutOverlap) {
  test::Flight f = test::fly(kWaitMission);
  std::string svg = trace::plot_svg(f.result, f.events);
  // A's If and B's WaitUntil (false) at t = 0, later the WaitUntil true: all labelled.
  EXPECT_NE(svg.find(">If → false</text>"), std::string::npos) << svg;
  EXPECT_NE(svg.find(">WaitUntil → true</text>"), std::string::npos);
  // Labels on one line (same y) never share horizontal space: different x by their widths.
  std::vector<std::string> xs = attrs(svg, "font-size=\"9.5\" fill=\"#", "x");
  std::vector<std::string> ys = attrs(svg, "font-size=\"9.5\" fill=\"#", "y");
  ASSERT_EQ(xs.size(), ys.size());
  ASSERT_GE(xs.size(), 3u);
  for (std::size_t i = 0; i < xs.size(); ++i)
    for (std::size_t j = i + 1; j < xs.size(); ++j)
      if (ys[i] == ys[j]) {
        EXPECT_GT(std::abs(std::stod(xs[i]) - std::stod(xs[j])), 60) << xs[i] << " " << xs[j];
      }
}

TEST(Plot, DrawsTheFailsafePhaseOnTheTimelineTheMapAndTheAltitude) {
  test::Flight f = test::fly(
      "var A Quad\nvar B Quad\n"
      "func INIT() { PAR_go() }\n"
      "func PAR_go() { SEQ_a(); SEQ_b() }\n"
      "func SEQ_a() { A.Arm(); A.Takeoff(5); A.Takeoff(A.Z() + 195) }\n"
      "func SEQ_b() { B.Arm(); B.Takeoff(8); B.FlyByY(20) }\n");
  ASSERT_FALSE(f.result.completed);
  std::string svg = trace::plot_svg(f.result, f.events);
  EXPECT_EQ(attrs(svg, "<g class=\"failsafe\"", "data-drone"), (std::vector<std::string>{"A", "B"})) << svg;
  std::vector<std::string> until = attrs(svg, "<g class=\"failsafe\"", "data-until");
  std::vector<std::string> from = attrs(svg, "<g class=\"failsafe\"", "data-from");
  ASSERT_EQ(until.size(), 2u);
  EXPECT_GT(std::stod(until[0]), std::stod(from[0]) + 1);  // it lasts until the drone is down
  EXPECT_EQ(count(svg, "<polyline class=\"failsafe\""), 2);
  EXPECT_EQ(count(svg, "class=\"altitude-failsafe\""), 2);
  EXPECT_NE(svg.find(">failsafe: land</text>"), std::string::npos);
}

TEST(Plot, TenDronesGetTenColours) {
  std::string text, par;
  for (int d = 0; d < 10; ++d) {
    text += "var D" + std::to_string(d) + " Quad\n";
    par += "D" + std::to_string(d) + ".Arm(); ";
  }
  text += "func INIT() { PAR_all() }\nfunc PAR_all() { " + par + "}\n";
  test::Flight f = test::fly(text);
  ASSERT_TRUE(f.result.completed) << f.result.error;
  std::string svg = trace::plot_svg(f.result, f.events);
  std::vector<std::string> colours = attrs(svg, "class=\"altitude\"", "stroke");
  ASSERT_EQ(colours.size(), 10u);
  std::sort(colours.begin(), colours.end());
  EXPECT_EQ(std::unique(colours.begin(), colours.end()), colours.end());
}

}  // namespace
}  // namespace eamos
