// The picture of a run (`eamos run --plot`): a tiny two-drone mission flown in the
// simulator, drawn, and checked for its parts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
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

// A fleet of `drones`: each arms, takes off, flies `k + 1` m east (drone k) and lands, then all
// disarm together (a fleet-wide barrier: every drone waits for the one that flew farthest).
// `first` replaces drone 0's flight when given.
std::string fleet_mission(int drones, const std::string& first = "") {
  std::string text, par, down;
  for (int d = 0; d < drones; ++d) {
    std::string n = "D" + std::to_string(d);
    text += "var " + n + " Quad\n";
    par += "SEQ_" + n + "(); ";
    down += n + ".Disarm(); ";
  }
  text += "func INIT() { PAR_go(); PAR_down() }\nfunc PAR_go() { " + par + "}\nfunc PAR_down() { " + down + "}\n";
  for (int d = 0; d < drones; ++d) {
    std::string n = "D" + std::to_string(d);
    std::string flight = d == 0 && !first.empty() ? first
                                                  : n + ".Takeoff(3); " + n + ".FlyByX(" + std::to_string(d + 1) + "); ";
    text += "func SEQ_" + n + "() { " + n + ".Arm(); " + flight + n + ".Land() }\n";
  }
  return text;
}

std::vector<int> numbers(const std::string& list) {
  std::vector<int> out;
  std::istringstream in(list);
  for (int v; in >> v;) out.push_back(v);
  return out;
}

TEST(Plot, FortyDronesKeepARowEachAndNoSummary) {
  test::Flight f = test::fly(fleet_mission(40));
  ASSERT_TRUE(f.result.completed) << f.result.error;
  std::string svg = trace::plot_svg(f.result, f.events);
  EXPECT_EQ(count(svg, "<g class=\"row\""), 40);
  EXPECT_EQ(count(svg, "class=\"altitude\""), 40);
  EXPECT_EQ(count(svg, "class=\"state-band\""), 0);
  EXPECT_EQ(count(svg, "class=\"thin-track\""), 0);
}

TEST(Plot, FiftyDronesAreSummarisedByStateAndTheTenThatHeldTheFleetUpGetRows) {
  test::Flight f = test::fly(fleet_mission(50));
  ASSERT_TRUE(f.result.completed) << f.result.error;
  std::string svg = trace::plot_svg(f.result, f.events);
  // Rows: the ten that flew farthest (all end together at the last barrier).
  std::vector<std::string> rows = attrs(svg, "<g class=\"row\"", "data-drone");
  std::vector<std::string> farthest;
  for (int d = 40; d < 50; ++d) farthest.push_back("D" + std::to_string(d));
  EXPECT_EQ(rows, farthest);
  EXPECT_EQ(attrs(svg, "class=\"altitude\"", "data-drone"), farthest);
  EXPECT_EQ(count(svg, "class=\"altitude-range\""), 1);
  EXPECT_EQ(count(svg, "class=\"thin-track\""), 50);
  EXPECT_EQ(attrs(svg, "class=\"track-name\"", "x").size(), 10u);
  // Every column of the state band counts each of the 50 drones once.
  std::vector<std::string> states = attrs(svg, "<path class=\"state\"", "data-state");
  EXPECT_EQ(states, (std::vector<std::string>{"flying", "waiting", "done", "failed"}));
  std::vector<std::string> counts = attrs(svg, "<path class=\"state\"", "data-counts");
  ASSERT_EQ(counts.size(), 4u);
  std::vector<std::vector<int>> per_state;
  for (const std::string& c : counts) per_state.push_back(numbers(c));
  ASSERT_GT(per_state[0].size(), 100u);
  for (std::size_t k = 0; k < per_state[0].size(); ++k)
    EXPECT_EQ(per_state[0][k] + per_state[1][k] + per_state[2][k] + per_state[3][k], 50) << "column " << k;
  EXPECT_EQ(per_state[0].front(), 50) << "all fly (arm, take off) at the start";
  EXPECT_EQ(per_state[2].back(), 50) << "all are done at the end";
  EXPECT_EQ(*std::max_element(per_state[3].begin(), per_state[3].end()), 0) << "none failed";
  EXPECT_GT(*std::max_element(per_state[1].begin(), per_state[1].end()), 40) << "all but the last wait at the barrier";
  // D40 waited at the barrier on the drones still flying, D49 among them (named in full in data-on).
  std::vector<std::string> who = attrs(svg, "<g class=\"wait\"", "data-drone");
  std::vector<std::string> on = attrs(svg, "<g class=\"wait\"", "data-on");
  auto d40 = std::find(who.begin(), who.end(), "D40");
  ASSERT_NE(d40, who.end()) << svg;
  EXPECT_NE(on[d40 - who.begin()].find("D49"), std::string::npos) << on[d40 - who.begin()];
  EXPECT_EQ(count(svg, "class=\"trigger\""), 0) << "no arrows across the few rows";
}

TEST(Plot, InASummaryTheDroneWhoseActionFailedHasARowAndTheBandCountsTheFailsafes) {
  test::Flight f = test::fly(fleet_mission(50, "D0.Takeoff(5); D0.Takeoff(D0.Z() + 195); "));
  ASSERT_FALSE(f.result.completed);
  std::string svg = trace::plot_svg(f.result, f.events);
  std::vector<std::string> rows = attrs(svg, "<g class=\"row\"", "data-drone");
  ASSERT_FALSE(rows.empty());
  EXPECT_EQ(rows.front(), "D0");
  EXPECT_LE(rows.size(), 10u);
  EXPECT_GE(count(svg, "data-outcome=\"failed\""), 1);
  std::vector<std::string> counts = attrs(svg, "<path class=\"state\"", "data-counts");
  ASSERT_EQ(counts.size(), 4u);
  std::vector<int> failed = numbers(counts[3]);
  EXPECT_EQ(failed.front(), 0);
  EXPECT_EQ(failed.back(), 50) << "every drone ends in its failsafe";
}

// The run keeps for the picture what it draws: a 1,000-drone show's k² barrier messages
// held 19 GB, and telemetry is never drawn (the tracks come from the run's result).
TEST(Plot, TheRunKeepsNoTelemetryForThePictureAndNoMessagesBeyondFortyDrones) {
  dex::TraceEvent message, telemetry, start;
  message.event = "message";
  telemetry.event = "telemetry";
  start.event = "start";
  trace::PlotTrace small(40), large(41);
  for (trace::PlotTrace* p : {&small, &large})
    for (const dex::TraceEvent* e : {&message, &telemetry, &start}) p->record(*e);
  EXPECT_TRUE(small.takes_messages());
  EXPECT_FALSE(large.takes_messages()) << "the runner then builds none";
  ASSERT_EQ(small.events.size(), 2u);
  EXPECT_EQ(small.events[0].event, "message");
  ASSERT_EQ(large.events.size(), 1u);
  EXPECT_EQ(large.events[0].event, "start");
}

}  // namespace
}  // namespace eamos
