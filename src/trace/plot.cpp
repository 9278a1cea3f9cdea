#include "trace/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <set>
#include <tuple>
#include <unordered_map>

#include "diag/xml.h"
#include "graph/palette.h"

namespace eamos::trace {

using dex::DroneSummary;
using dex::RunResult;
using dex::Sample;
using dex::TraceEvent;

namespace {

constexpr double kWidth = 960;         ///< whole picture, px
constexpr double kLeft = 110;          ///< left edge of both panels' plot areas (row names go left of it)
constexpr double kMapRight = 780;      ///< right edge of the map (its legend goes right of it)
constexpr double kMapMaxHeight = 420;  ///< the map is at most this tall, px
constexpr double kRight = 930;         ///< right edge of the timeline
constexpr double kLaneHeight = 20;     ///< one lane of timeline bars
constexpr double kBarHeight = 15;
constexpr double kTickStrip = 10;      ///< top strip of a timeline row for condition ticks
constexpr double kCharWidth = 6.3;     ///< estimated width of one character at font-size 11
const char* kFont = "Helvetica, Arial, sans-serif";
const char* kGround = "#999999";       ///< track on the ground
const char* kLanded = "#009E73";

/// One colour per drone, the same as in `eamos graph` (graph/palette.h).
std::string drone_colour(int d) { return graph::drone_colour(d); }
const char* kFailsafe = "#D62728";
const char* kWait = "#7A0177";  ///< cross-drone waits: the colour of cross-drone arcs in the graphs
constexpr double kAltitudeHeight = 130;  ///< the altitude panel's plot area, px
constexpr double kConditionLane = 13;    ///< one lane of condition marks and their labels

const char* outcome_colour(const std::string& outcome) {
  if (outcome == "succeeded") return "#009E73";
  if (outcome == "preempted") return "#E69F00";
  if (outcome == "cancelled") return "#999999";
  if (outcome == "failed") return "#D55E00";
  return "#56B4E9";  // still running when the run ended
}

std::string xml(const std::string& s) { return diag::xml_escape(s); }

/// Fixed-point number without trailing zeros ("12.5", "3", "-0.25").
std::string num(double v, int decimals = 2) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s = buf;
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

/// A round tick step (1, 2 or 5 times a power of ten) giving about `ticks` ticks over `span`.
double nice_step(double span, int ticks) {
  double raw = span / ticks;
  double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (raw <= m * p) return m * p;
  return 10 * p;
}

/// A diamond 12 px across centred on (x, y).
std::string diamond(double x, double y) {
  return "M" + num(x) + "," + num(y - 6) + " l6,6 l-6,6 l-6,-6 z";
}

std::string text(double x, double y, const std::string& s, const std::string& attrs = "") {
  return "<text x=\"" + num(x) + "\" y=\"" + num(y) + "\"" + (attrs.empty() ? "" : " " + attrs) + ">" +
         xml(s) + "</text>\n";
}

/// "Drone1.Takeoff(3)" in Drone1's row reads "Takeoff(3)".
std::string without_drone(const std::string& s, const std::string& drone) {
  std::string prefix = drone + ".";
  return s.rfind(prefix, 0) == 0 ? s.substr(prefix.size()) : s;
}

/// Each drone's events named `event`, in trace order: one pass over a trace that may hold
/// millions of events, not one per drone.
std::vector<std::vector<const TraceEvent*>> per_drone(const RunResult& run, const std::vector<TraceEvent>& events,
                                                      const std::string& event) {
  std::unordered_map<std::string, std::size_t> row;
  for (std::size_t d = 0; d < run.drones.size(); ++d) row.emplace(run.drones[d].name, d);
  std::vector<std::vector<const TraceEvent*>> out(run.drones.size());
  for (const TraceEvent& e : events) {
    if (e.event != event) continue;
    auto r = row.find(e.drone);
    if (r != row.end()) out[r->second].push_back(&e);
  }
  return out;
}

struct Bar {
  double start = 0, end = 0;
  std::string text, outcome, reason;
  int line = 0;
  int lane = 0;
  bool label_left = false;  ///< the label ends left of the bar (no room right of it)
};

/// Each drone's action bars: a start event paired with the next end event of the same
/// action (drone, line, text); an action with no end runs to `until`.
std::vector<std::vector<Bar>> bars_of(const RunResult& run, const std::vector<TraceEvent>& events, double until) {
  std::map<std::string, int> row;
  for (std::size_t d = 0; d < run.drones.size(); ++d) row[run.drones[d].name] = static_cast<int>(d);
  std::vector<std::vector<Bar>> bars(run.drones.size());
  std::map<std::tuple<std::string, int, std::string>, std::vector<std::size_t>> open;
  for (const TraceEvent& e : events) {
    auto r = row.find(e.drone);
    if (r == row.end()) continue;
    auto key = std::make_tuple(e.drone, e.line, e.text);
    if (e.event == "start") {
      open[key].push_back(bars[r->second].size());
      bars[r->second].push_back({e.t, until, e.text, "", "", e.line, 0});
    } else if (e.event == "end" && !open[key].empty()) {
      Bar& b = bars[r->second][open[key].front()];
      open[key].erase(open[key].begin());
      b.end = e.t;
      b.outcome = e.outcome;
      b.reason = e.reason;
    }
  }
  return bars;
}

// ---- top panel -------------------------------------------------------------------------

struct MapFrame {
  double x0, y0, scale;  ///< metres at the plot area's left/bottom edge; px per metre
  double top, bottom;    ///< px
  double to_x(double x) const { return kLeft + (x - x0) * scale; }
  double to_y(double y) const { return bottom - (y - y0) * scale; }
};

MapFrame map_frame(const RunResult& run, double top) {
  double lo_x = 0, hi_x = 0, lo_y = 0, hi_y = 0;
  bool any = false;
  for (const auto& d : run.drones)
    for (const Sample& s : d.track) {
      if (!any) lo_x = hi_x = s.x, lo_y = hi_y = s.y, any = true;
      lo_x = std::min(lo_x, s.x), hi_x = std::max(hi_x, s.x);
      lo_y = std::min(lo_y, s.y), hi_y = std::max(hi_y, s.y);
    }
  // Room around the tracks for markers and names: 10 % and at least 2 m.
  double pad = std::max(2.0, 0.1 * std::max(hi_x - lo_x, hi_y - lo_y));
  lo_x -= pad, hi_x += pad, lo_y -= pad, hi_y += pad;
  double width = kMapRight - kLeft;
  double scale = std::min(width / (hi_x - lo_x), kMapMaxHeight / (hi_y - lo_y));
  // Equal scale: widen the x range to the panel's width, centred.
  double cx = (lo_x + hi_x) / 2;
  MapFrame f;
  f.scale = scale;
  f.x0 = cx - width / scale / 2;
  f.y0 = lo_y;
  f.top = top;
  f.bottom = top + (hi_y - lo_y) * scale;
  return f;
}

void map_axes(std::ostream& out, const MapFrame& f) {
  double x1 = f.x0 + (kMapRight - kLeft) / f.scale;
  double y1 = f.y0 + (f.bottom - f.top) / f.scale;
  double step = nice_step(std::max(x1 - f.x0, y1 - f.y0), 10);
  out << "<g class=\"map-axes\" font-size=\"11\" fill=\"#444444\">\n";
  for (double x = std::ceil(f.x0 / step) * step; x <= x1 + 1e-9; x += step) {
    double px = f.to_x(x);
    out << "<line x1=\"" << num(px) << "\" y1=\"" << num(f.top) << "\" x2=\"" << num(px) << "\" y2=\""
        << num(f.bottom + 4) << "\" stroke=\"" << (std::abs(x) < 1e-9 ? "#cccccc" : "#eeeeee") << "\"/>\n";
    out << text(px, f.bottom + 16, num(x), "text-anchor=\"middle\"");
  }
  for (double y = std::ceil(f.y0 / step) * step; y <= y1 + 1e-9; y += step) {
    double py = f.to_y(y);
    out << "<line x1=\"" << num(kLeft - 4) << "\" y1=\"" << num(py) << "\" x2=\"" << num(kMapRight)
        << "\" y2=\"" << num(py) << "\" stroke=\"" << (std::abs(y) < 1e-9 ? "#cccccc" : "#eeeeee") << "\"/>\n";
    out << text(kLeft - 7, py + 4, num(y), "text-anchor=\"end\"");
  }
  out << "<rect x=\"" << num(kLeft) << "\" y=\"" << num(f.top) << "\" width=\"" << num(kMapRight - kLeft)
      << "\" height=\"" << num(f.bottom - f.top) << "\" fill=\"none\" stroke=\"#888888\"/>\n";
  out << text((kLeft + kMapRight) / 2, f.bottom + 32, "x (m, east)", "text-anchor=\"middle\"");
  out << text(kLeft - 45, (f.top + f.bottom) / 2, "y (m, north)",
              "text-anchor=\"middle\" transform=\"rotate(-90 " + num(kLeft - 45) + " " +
                  num((f.top + f.bottom) / 2) + ")\"");
  out << "</g>\n";
}

/// One drone's track: runs of segments on the ground (grey, dashed) and in the air
/// (solid, the drone's colour), then the armed, landed and start markers.
void map_track(std::ostream& out, const MapFrame& f, const DroneSummary& drone, int d,
               const std::vector<double>& failsafe_from) {
  const std::vector<Sample>& s = drone.track;
  if (s.empty()) return;
  out << "<g class=\"track\" data-drone=\"" << xml(drone.name) << "\">\n";
  std::size_t i = 0;
  while (i + 1 < s.size()) {
    bool air = !s[i].landed;
    std::size_t j = i + 1;
    while (j + 1 < s.size() && !s[j].landed == air) ++j;
    // Points closer than half a pixel to the last kept one add nothing to the picture.
    std::string points = num(f.to_x(s[i].x)) + "," + num(f.to_y(s[i].y));
    double lx = f.to_x(s[i].x), ly = f.to_y(s[i].y);
    for (std::size_t k = i + 1; k <= j; ++k) {
      double px = f.to_x(s[k].x), py = f.to_y(s[k].y);
      if (k < j && std::hypot(px - lx, py - ly) < 0.5) continue;
      points += " " + num(px) + "," + num(py);
      lx = px, ly = py;
    }
    out << "<polyline class=\"" << (air ? "air" : "ground") << "\" points=\"" << points
        << "\" fill=\"none\" stroke-linejoin=\"round\" stroke-linecap=\"round\" "
        << (air ? std::string("stroke=\"") + drone_colour(d) + "\" stroke-width=\"2.5\""
                : std::string("stroke=\"") + kGround + "\" stroke-width=\"1.5\" stroke-dasharray=\"4 3\"")
        << "/>\n";
    i = j;
  }
  // The failsafe's part of the track, dashed red over it: where the drone went once the
  // mission was abandoned.
  for (double from : failsafe_from) {
    std::string points;
    for (const Sample& p : s)
      if (p.t >= from) points += (points.empty() ? "" : " ") + num(f.to_x(p.x)) + "," + num(f.to_y(p.y));
    if (!points.empty())
      out << "<polyline class=\"failsafe\" points=\"" << points << "\" fill=\"none\" stroke=\"" << kFailsafe
          << "\" stroke-width=\"2\" stroke-dasharray=\"5 3\"/>\n";
  }
  double sx = f.to_x(s[0].x), sy = f.to_y(s[0].y);
  out << "<circle class=\"start\" cx=\"" << num(sx) << "\" cy=\"" << num(sy) << "\" r=\"6\" fill=\"#ffffff\" stroke=\""
      << drone_colour(d) << "\" stroke-width=\"2\"><title>" << xml(drone.name) << " starts at " << num(s[0].x) << ", "
      << num(s[0].y) << " m</title></circle>\n";
  for (std::size_t k = 1; k < s.size(); ++k) {
    double px = f.to_x(s[k].x), py = f.to_y(s[k].y);
    if (s[k].armed && !s[k - 1].armed && s[k].landed)
      out << "<rect class=\"armed\" x=\"" << num(px - 3) << "\" y=\"" << num(py - 3)
          << "\" width=\"6\" height=\"6\" fill=\"#000000\"><title>" << xml(drone.name) << " armed at "
          << num(s[k].t) << " s</title></rect>\n";
    if (s[k].landed && !s[k - 1].landed)
      out << "<path class=\"landed\" d=\"" << diamond(px, py) << "\" fill=\"" << kLanded
          << "\" stroke=\"#222222\"><title>" << xml(drone.name) << " landed at " << num(s[k].t)
          << " s</title></path>\n";
  }
  // The name left of the start, on a white halo so crossing tracks do not hide it.
  out << text(sx - 10, sy + 4, drone.name,
              std::string("text-anchor=\"end\" font-size=\"12\" font-weight=\"bold\" stroke=\"#ffffff\" "
                          "stroke-width=\"4\" paint-order=\"stroke\" stroke-linejoin=\"round\" fill=\"") +
                  drone_colour(d) + "\"");
  out << "</g>\n";
}

/// A large fleet's track: one thin line in the drone's colour (points closer than 1.5 px to
/// the last one kept left out), its failsafe's part red; named only when `named`.
void map_thin_track(std::ostream& out, const MapFrame& f, const DroneSummary& drone, int d,
                    const std::vector<double>& failsafe_from, bool named) {
  const std::vector<Sample>& s = drone.track;
  if (s.empty()) return;
  std::string points;
  double lx = 0, ly = 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    double px = f.to_x(s[k].x), py = f.to_y(s[k].y);
    if (k > 0 && k + 1 < s.size() && std::hypot(px - lx, py - ly) < 1.5) continue;
    points += (points.empty() ? "" : " ") + num(px, 1) + "," + num(py, 1);
    lx = px, ly = py;
  }
  out << "<polyline class=\"thin-track\" data-drone=\"" << xml(drone.name) << "\" points=\"" << points
      << "\" fill=\"none\" stroke=\"" << drone_colour(d) << "\" stroke-width=\"0.7\" stroke-opacity=\"0.7\"/>\n";
  if (!failsafe_from.empty()) {
    auto from = std::lower_bound(s.begin(), s.end(), failsafe_from.front(),
                                 [](const Sample& p, double t) { return p.t < t; });
    std::string red;
    for (auto p = from; p != s.end(); ++p) red += (red.empty() ? "" : " ") + num(f.to_x(p->x), 1) + "," + num(f.to_y(p->y), 1);
    if (!red.empty())
      out << "<polyline class=\"failsafe\" data-drone=\"" << xml(drone.name) << "\" points=\"" << red
          << "\" fill=\"none\" stroke=\"" << kFailsafe << "\" stroke-width=\"1\" stroke-dasharray=\"3 2\"/>\n";
  }
  if (named)
    out << text(f.to_x(s.back().x) + 5, f.to_y(s.back().y) - 4, drone.name,
                std::string("class=\"track-name\" font-size=\"10\" font-weight=\"bold\" stroke=\"#ffffff\" stroke-width=\"3\" "
                            "paint-order=\"stroke\" fill=\"") + drone_colour(d) + "\"");
}

void map_legend_many(std::ostream& out, const RunResult& run, double top) {
  double x = kMapRight + 20, y = top + 12;
  out << "<g class=\"legend\" font-size=\"11\" fill=\"#222222\">\n";
  out << text(x, y, std::to_string(run.drones.size()) + " drones:");
  out << text(x, y + 16, "a thin line each,");
  out << text(x, y + 32, "in its colour");
  y += 58;
  out << text(x, y, "named: the drones");
  out << text(x, y + 16, "with a row below");
  y += 40;
  out << "<line x1=\"" << num(x) << "\" y1=\"" << num(y - 4) << "\" x2=\"" << num(x + 22) << "\" y2=\"" << num(y - 4)
      << "\" stroke=\"" << kFailsafe << "\" stroke-width=\"1\" stroke-dasharray=\"3 2\"/>\n";
  out << text(x + 30, y, "failsafe");
  out << "</g>\n";
}

void map_legend(std::ostream& out, const RunResult& run, double top) {
  double x = kMapRight + 20, y = top + 12;
  out << "<g class=\"legend\" font-size=\"11\" fill=\"#222222\">\n";
  for (std::size_t d = 0; d < run.drones.size(); ++d, y += 18) {
    out << "<line x1=\"" << num(x) << "\" y1=\"" << num(y - 4) << "\" x2=\"" << num(x + 22) << "\" y2=\""
        << num(y - 4) << "\" stroke=\"" << drone_colour(static_cast<int>(d)) << "\" stroke-width=\"2.5\"/>\n";
    out << text(x + 30, y, run.drones[d].name);
  }
  y += 8;
  out << "<line x1=\"" << num(x) << "\" y1=\"" << num(y - 4) << "\" x2=\"" << num(x + 22) << "\" y2=\"" << num(y - 4)
      << "\" stroke=\"" << kGround << "\" stroke-width=\"1.5\" stroke-dasharray=\"4 3\"/>\n";
  out << text(x + 30, y, "on the ground");
  y += 18;
  out << "<circle cx=\"" << num(x + 11) << "\" cy=\"" << num(y - 4) << "\" r=\"6\" fill=\"#ffffff\" stroke=\"#444444\" stroke-width=\"2\"/>\n";
  out << text(x + 30, y, "start");
  y += 18;
  out << "<rect x=\"" << num(x + 8) << "\" y=\"" << num(y - 7) << "\" width=\"6\" height=\"6\" fill=\"#000000\"/>\n";
  out << text(x + 30, y, "armed");
  y += 18;
  out << "<path d=\"" << diamond(x + 11, y - 4) << "\" fill=\"" << kLanded << "\" stroke=\"#222222\"/>\n";
  out << text(x + 30, y, "landed");
  y += 18;
  out << "<line x1=\"" << num(x) << "\" y1=\"" << num(y - 4) << "\" x2=\"" << num(x + 22) << "\" y2=\"" << num(y - 4)
      << "\" stroke=\"" << kFailsafe << "\" stroke-width=\"2\" stroke-dasharray=\"5 3\"/>\n";
  out << text(x + 30, y, "failsafe");
  out << "</g>\n";
}

// ---- bottom panel ----------------------------------------------------------------------

double time_x(double t, double until) { return kLeft + t / until * (kRight - kLeft); }

/// Lanes so that no two bars, labels included, overlap; returns the number of lanes. A
/// label goes right of its bar's start, or left of it near the panel's right edge.
int pack_lanes(std::vector<Bar>& bars, const std::string& drone, double until) {
  std::vector<std::vector<std::pair<double, double>>> lanes;  // occupied px intervals
  for (Bar& b : bars) {
    double x0 = time_x(b.start, until), x1 = time_x(b.end, until);
    double label = without_drone(b.text, drone).size() * kCharWidth + 8;
    b.label_left = x0 + label > kWidth - 4;
    double from = b.label_left ? x0 - label : x0, to = b.label_left ? x1 : std::max(x1, x0 + label);
    std::size_t l = 0;
    auto overlaps = [&](const std::pair<double, double>& i) { return i.first < to + 4 && from < i.second + 4; };
    while (l < lanes.size() && std::any_of(lanes[l].begin(), lanes[l].end(), overlaps)) ++l;
    if (l == lanes.size()) lanes.emplace_back();
    lanes[l].push_back({from, to});
    b.lane = static_cast<int>(l);
  }
  return std::max<int>(1, static_cast<int>(lanes.size()));
}

/// A condition decision in a row: a tick at its time with its label ("If → false"), in
/// lanes so that no two labels overlap.
struct ConditionMark {
  double t = 0;
  std::string name, text;
  bool value = false;
  int lane = 0;
};

std::string condition_label(const ConditionMark& c) { return c.name + " → " + (c.value ? "true" : "false"); }

/// Each drone's condition marks, lanes assigned; returns the lanes per drone (at least 1).
std::vector<int> condition_marks(const RunResult& run, const std::vector<TraceEvent>& events, double until,
                                 std::vector<std::vector<ConditionMark>>& marks) {
  marks.assign(run.drones.size(), {});
  std::vector<int> lanes(run.drones.size(), 1);
  std::vector<std::vector<const TraceEvent*>> of_drone = per_drone(run, events, "condition");
  for (std::size_t d = 0; d < run.drones.size(); ++d) {
    std::vector<std::vector<std::pair<double, double>>> used;
    for (const TraceEvent* c : of_drone[d]) {
      const TraceEvent& e = *c;
      ConditionMark m{e.t, e.name, e.text, e.value.value_or(false), 0};
      double x = time_x(m.t, until), width = condition_label(m).size() * kCharWidth * 0.85 + 12;
      bool left = x + width > kWidth - 4;  // near the right edge the label ends at the tick
      double from = left ? x - width : x - 5, to = left ? x + 5 : x + width;
      std::size_t l = 0;
      auto overlaps = [&](const std::pair<double, double>& i) { return i.first < to && from < i.second; };
      while (l < used.size() && std::any_of(used[l].begin(), used[l].end(), overlaps)) ++l;
      if (l == used.size()) used.emplace_back();
      used[l].push_back({from, to});
      m.lane = static_cast<int>(l);
      marks[d].push_back(m);
    }
    lanes[d] = std::max<int>(1, static_cast<int>(used.size()));
  }
  return lanes;
}

void draw_condition(std::ostream& out, const ConditionMark& m, double lane_top, double until) {
  double px = time_x(m.t, until);
  const char* c = m.value ? "#009E73" : "#D55E00";
  std::string label = condition_label(m);
  bool left = px + label.size() * kCharWidth * 0.85 + 12 > kWidth - 4;
  out << "<g class=\"condition\" data-condition=\"" << xml(m.name) << "\" data-value=\"" << (m.value ? "true" : "false")
      << "\"><title>" << xml(m.name + " " + m.text) << " → " << (m.value ? "true" : "false") << " at " << num(m.t)
      << " s</title>\n";
  out << "<path d=\"M" << num(px - 4) << "," << num(lane_top + 2) << " l8,0 l-4,7 z\" fill=\"" << c << "\"/>\n";
  out << text(left ? px - 6 : px + 6, lane_top + 9, label,
              std::string("font-size=\"9.5\" fill=\"") + c + "\"" + (left ? " text-anchor=\"end\"" : ""));
  out << "</g>\n";
}

/// A drone that waited on others: from its last action's end until a trigger from another
/// drone started its next action.
struct Wait {
  int drone = 0;                       ///< who waited
  double from = 0, until = 0;          ///< mission s
  std::vector<int> on;                 ///< whom it waited on (the triggers' senders)
  std::vector<double> sent;            ///< when each sent its trigger
};

/// Where each drone's events are in the trace, so that waits_of asks its questions in
/// O(log n) instead of rescanning a trace of millions of events once per message.
struct TraceIndex {
  std::vector<double> t;  ///< each event's time
  std::vector<int> drone;  ///< each event's drone, -1 for none
  std::vector<std::vector<std::size_t>> starts, ends, triggers_to;  ///< per drone: indices into the trace
};

TraceIndex index_trace(const RunResult& run, const std::vector<TraceEvent>& events) {
  std::unordered_map<std::string, int> row;
  for (std::size_t d = 0; d < run.drones.size(); ++d) row.emplace(run.drones[d].name, static_cast<int>(d));
  TraceIndex x;
  x.starts.resize(run.drones.size());
  x.ends.resize(run.drones.size());
  x.triggers_to.resize(run.drones.size());
  x.t.reserve(events.size());
  x.drone.reserve(events.size());
  for (std::size_t i = 0; i < events.size(); ++i) {
    const TraceEvent& e = events[i];
    x.t.push_back(e.t);
    auto r = row.find(e.drone);
    x.drone.push_back(r == row.end() ? -1 : r->second);
    if (r != row.end() && e.event == "start") x.starts[r->second].push_back(i);
    if (r != row.end() && e.event == "end") x.ends[r->second].push_back(i);
    if (e.event == "message" && e.kind == "trigger" && e.to >= 0 && e.to < static_cast<int>(run.drones.size()))
      x.triggers_to[e.to].push_back(i);
  }
  return x;
}

/// The last index in `list` (ascending) within [lo, hi), or -1.
long last_in(const std::vector<std::size_t>& list, std::size_t lo, std::size_t hi) {
  auto it = std::lower_bound(list.begin(), list.end(), hi);
  return it == list.begin() || *(it - 1) < lo ? -1 : static_cast<long>(*(it - 1));
}

/// A message that drone `m.from` only passed on: it arrived there at the instant it was
/// sent on, before any action of that drone ended then (a terminal or fork the drone holds
/// relayed another drone's trigger). Returns the index of the message it passed on, or -1.
/// The events just before k at the instant it was sent are a range (the trace is in time order).
long relayed_from(const TraceIndex& x, const std::vector<TraceEvent>& events, std::size_t k) {
  const TraceEvent& m = events[k];
  const int n = static_cast<int>(x.ends.size());
  if (k == 0 || std::abs(x.t[k - 1] - m.sent) > 1e-6 || m.from < 0 || m.from >= n) return -1;
  auto lo = static_cast<std::size_t>(std::lower_bound(x.t.begin(), x.t.begin() + static_cast<long>(k), m.sent - 1e-6) -
                                     x.t.begin());
  if (last_in(x.ends[m.from], lo, k) >= 0) return -1;  // its own action ended then: its own trigger
  return last_in(x.triggers_to[m.from], lo, k);
}

/// The waits in `events`: a `trigger` message that arrived at t at a drone that started an
/// action at t, after it had been idle since earlier (a wait of at least 50 ms): since its
/// last action ended or it last sent a message of its own (a condition it holds ran). A
/// trigger relayed through another drone's terminal is counted from where it came from.
/// One pass over the trace: each drone's idle-since time is kept as the pass goes.
std::vector<Wait> waits_of(const RunResult& run, const std::vector<TraceEvent>& events) {
  const int n = static_cast<int>(run.drones.size());
  TraceIndex x = index_trace(run, events);
  std::vector<double> busy_until(run.drones.size(), -1);
  std::vector<Wait> waits;
  std::map<std::pair<int, double>, std::size_t> wait_at;  // (drone, until) -> its wait
  std::set<std::pair<std::size_t, int>> counted;           // (wait, on)
  for (std::size_t i = 0; i < events.size(); ++i) {
    const TraceEvent& m = events[i];
    bool trigger = m.event == "message" && m.kind == "trigger" && m.to >= 0 && m.to < n && m.from >= 0 && m.from < n;
    if (trigger) {
      auto next = std::lower_bound(x.starts[m.to].begin(), x.starts[m.to].end(), i);
      bool starts = next != x.starts[m.to].end() && std::abs(events[*next].t - m.t) < 1e-6;
      if (starts && busy_until[m.to] >= 0 && m.t - busy_until[m.to] >= 0.05) {
        std::size_t origin = i;
        for (long r; (r = relayed_from(x, events, origin)) >= 0;) origin = static_cast<std::size_t>(r);
        int on = events[origin].from;
        if (on >= 0 && on < n && on != m.to) {
          auto [at, added] = wait_at.emplace(std::make_pair(m.to, m.t), waits.size());
          if (added) waits.push_back({m.to, busy_until[m.to], m.t, {}, {}});
          if (counted.emplace(at->second, on).second) {
            waits[at->second].on.push_back(on);
            waits[at->second].sent.push_back(events[origin].sent);
          }
        }
      }
    }
    if (x.drone[i] >= 0 && m.event == "end") busy_until[x.drone[i]] = std::max(busy_until[x.drone[i]], m.t);
    if (m.event == "message" && m.from >= 0 && m.from < n && relayed_from(x, events, i) < 0)
      busy_until[m.from] = std::max(busy_until[m.from], m.sent);
  }
  return waits;
}

/// Each failsafe: from the event until the drone was down (landed, or the end of the run).
struct FailsafePhase {
  int drone = 0;
  double from = 0, until = 0;
  std::string name, reason;
};

std::vector<FailsafePhase> failsafes_of(const RunResult& run, const std::vector<TraceEvent>& events, double end) {
  std::vector<FailsafePhase> phases;
  for (const TraceEvent& e : events) {
    if (e.event != "failsafe") continue;
    for (std::size_t d = 0; d < run.drones.size(); ++d) {
      if (run.drones[d].name != e.drone) continue;
      double down = end;
      for (const Sample& s : run.drones[d].track)
        if (s.t >= e.t && s.landed && !s.armed) {
          down = s.t;
          break;
        }
      phases.push_back({static_cast<int>(d), e.t, std::max(down, e.t), e.name, e.reason});
    }
  }
  return phases;
}

/// Where each drone's row of the timeline is, px.
struct RowGeometry {
  std::vector<double> top, bars_top;
  std::vector<int> lanes;
  std::vector<double> extra;  ///< a strip below the bars for the drone's waits
  std::vector<bool> shown;    ///< the drones that have a row (all of a small fleet)
  bool summary = false;       ///< a large fleet's few rows: long lists of drones are cut short
  double bottom(std::size_t d) const { return bars_top[d] + lanes[d] * kLaneHeight + 6 + extra[d]; }
  double middle(std::size_t d) const { return (bars_top[d] + bottom(d)) / 2; }
};

void draw_failsafes(std::ostream& out, const RunResult& run, const std::vector<FailsafePhase>& phases,
                    const RowGeometry& rows, double until) {
  for (const FailsafePhase& f : phases) {
    if (!rows.shown[f.drone]) continue;
    double x0 = time_x(f.from, until), x1 = std::max(time_x(f.until, until), x0 + 2);
    double y0 = rows.bars_top[f.drone], y1 = rows.bars_top[f.drone] + rows.lanes[f.drone] * kLaneHeight + 3;
    out << "<g class=\"failsafe\" data-drone=\"" << xml(run.drones[f.drone].name) << "\" data-from=\"" << num(f.from)
        << "\" data-until=\"" << num(f.until) << "\"><title>" << xml(run.drones[f.drone].name) << " failsafe ("
        << xml(f.name) << ") " << num(f.from) << "–" << num(f.until) << " s: " << xml(f.reason) << "</title>\n";
    out << "<rect x=\"" << num(x0) << "\" y=\"" << num(y0) << "\" width=\"" << num(x1 - x0) << "\" height=\""
        << num(y1 - y0) << "\" fill=\"url(#failsafe-hatch)\" stroke=\"" << kFailsafe << "\" stroke-dasharray=\"3 2\"/>\n";
    // At the band's far end: the action that failed (and led to it) is labelled at its start.
    out << text(x1 - 4, y0 + 11, "failsafe: " + f.name,
                std::string("font-size=\"10\" font-weight=\"bold\" text-anchor=\"end\" fill=\"") + kFailsafe + "\"");
    out << "</g>\n";
  }
}

/// A wait: a dotted bar in the waiting drone's row (from its last end to the trigger) and
/// an arrow from each sender's row at the time it sent to the waiting drone's.
void draw_waits(std::ostream& out, const RunResult& run, const std::vector<Wait>& waits, const RowGeometry& rows,
                double until) {
  for (const Wait& w : waits) {
    if (!rows.shown[w.drone]) continue;
    std::string on;
    for (int s : w.on) on += (on.empty() ? "" : ", ") + run.drones[s].name;
    std::string on_label = on;
    if (rows.summary && w.on.size() > 3)
      on_label = run.drones[w.on[0]].name + ", " + run.drones[w.on[1]].name + ", " + run.drones[w.on[2]].name +
                 " and " + std::to_string(w.on.size() - 3) + " more";
    std::string seconds = num(w.until - w.from);
    double x0 = time_x(w.from, until), x1 = time_x(w.until, until);
    double y = rows.bars_top[w.drone] + rows.lanes[w.drone] * kLaneHeight + 15;
    out << "<g class=\"wait\" data-drone=\"" << xml(run.drones[w.drone].name) << "\" data-on=\"" << xml(on)
        << "\" data-seconds=\"" << seconds << "\"><title>" << xml(run.drones[w.drone].name) << " waited " << seconds
        << " s on " << xml(on) << " (" << num(w.from) << "–" << num(w.until) << " s)</title>\n";
    out << "<line x1=\"" << num(x0) << "\" y1=\"" << num(y) << "\" x2=\"" << num(x1) << "\" y2=\"" << num(y)
        << "\" stroke=\"" << kWait << "\" stroke-width=\"2\" stroke-dasharray=\"2 2\"/>\n";
    for (std::size_t k = 0; k < w.on.size(); ++k) {
      // A large fleet's few rows: the senders mostly have no row, and a barrier's arrows
      // from the few that do would cover the rows; the title names them all.
      if (rows.summary || !rows.shown[w.on[k]]) continue;
      double sx = time_x(w.sent[k], until), sy = rows.middle(w.on[k]);
      double ty = rows.middle(w.drone) + (rows.middle(w.drone) > sy ? -6 : 6);
      out << "<line class=\"trigger\" x1=\"" << num(sx) << "\" y1=\"" << num(sy) << "\" x2=\"" << num(x1)
          << "\" y2=\"" << num(ty) << "\" stroke=\"" << kWait << "\" stroke-width=\"1.3\" marker-end=\"url(#arrow)\"/>\n";
    }
    // The label sits on the dotted bar, inside it when it fits, else left of its end.
    std::string label = "waits " + seconds + " s on " + on_label;
    bool fits = x1 - x0 > label.size() * kCharWidth * 0.85 + 6;
    if (rows.summary && !fits) {  // many short waits side by side: labels only where they fit
      out << "</g>\n";
      continue;
    }
    out << text(fits ? x0 + 3 : x1 - 3, y - 3, label,
                std::string("font-size=\"9.5\" fill=\"") + kWait + "\"" + (fits ? "" : " text-anchor=\"end\""));
    out << "</g>\n";
  }
}

/// Rows for the `shown` drones, top to bottom from `top`; lanes packed into `bars`.
RowGeometry row_geometry(const RunResult& run, std::vector<std::vector<Bar>>& bars,
                         const std::vector<std::vector<ConditionMark>>& conditions, const std::vector<int>& condition_lanes,
                         const std::vector<Wait>& waits, const std::vector<int>& shown, double top, double until) {
  const std::size_t n = run.drones.size();
  RowGeometry rows{std::vector<double>(n), std::vector<double>(n), std::vector<int>(n, 1), std::vector<double>(n),
                   std::vector<bool>(n, false)};
  std::vector<bool> waited(n, false);
  for (const Wait& w : waits) waited[w.drone] = true;
  double y = top;
  for (int d : shown) {
    rows.shown[d] = true;
    rows.lanes[d] = pack_lanes(bars[d], run.drones[d].name, until);
    rows.top[d] = y;
    double strip = conditions[d].empty() ? kTickStrip : condition_lanes[d] * kConditionLane + 2;
    rows.bars_top[d] = y + strip;
    rows.extra[d] = waited[d] ? 16 : 0;
    y = rows.bottom(d);
  }
  return rows;
}

/// Vertical grid lines from `top` to `bottom` with the time labels under them.
void time_axis(std::ostream& out, double top, double bottom, double until) {
  double step = nice_step(until, 12);
  out << "<g class=\"time-axis\" font-size=\"11\" fill=\"#444444\">\n";
  for (double t = 0; t <= until + 1e-9; t += step) {
    double px = time_x(t, until);
    out << "<line x1=\"" << num(px) << "\" y1=\"" << num(top) << "\" x2=\"" << num(px) << "\" y2=\""
        << num(bottom + 4) << "\" stroke=\"#eeeeee\"/>\n";
    out << text(px, bottom + 16, num(t), "text-anchor=\"middle\"");
  }
  out << text((kLeft + kRight) / 2, bottom + 32, "mission time (s)", "text-anchor=\"middle\"");
  out << "</g>\n";
}

/// One drone's row: its name, a bar per action and its condition marks.
void draw_row(std::ostream& out, const RunResult& run, std::size_t d, const std::vector<Bar>& bars,
              const std::vector<ConditionMark>& conditions, const RowGeometry& rows, double until) {
  const std::string& name = run.drones[d].name;
  double rt = rows.top[d];
  double rb = rows.bottom(d);
  out << "<g class=\"row\" data-drone=\"" << xml(name) << "\">\n";
  out << "<line x1=\"" << num(kLeft - 100) << "\" y1=\"" << num(rb) << "\" x2=\"" << num(kRight) << "\" y2=\""
      << num(rb) << "\" stroke=\"#cccccc\"/>\n";
  out << text(kLeft - 10, (rt + rb) / 2 + 4, name,
              std::string("text-anchor=\"end\" font-size=\"12\" font-weight=\"bold\" fill=\"") +
                  drone_colour(static_cast<int>(d)) + "\"");
  for (const Bar& b : bars) {
    double x0 = time_x(b.start, until), x1 = time_x(b.end, until);
    double by = rows.bars_top[d] + b.lane * kLaneHeight + (kLaneHeight - kBarHeight) / 2;
    const char* c = outcome_colour(b.outcome);
    std::string tip = b.text + " (line " + std::to_string(b.line) + "): " + num(b.start) + "–" + num(b.end) +
                      " s, " + (b.outcome.empty() ? "still running" : b.outcome) +
                      (b.reason.empty() ? "" : " (" + b.reason + ")");
    out << "<g data-action=\"" << xml(b.text) << "\" data-outcome=\"" << xml(b.outcome) << "\"><title>"
        << xml(tip) << "</title>\n";
    out << "<rect x=\"" << num(x0) << "\" y=\"" << num(by) << "\" width=\"" << num(std::max(x1 - x0, 2.0))
        << "\" height=\"" << num(kBarHeight) << "\" rx=\"2\" fill=\"" << c << "\" fill-opacity=\"0.3\" stroke=\""
        << c << "\"/>\n";
    out << text(b.label_left ? x0 - 4 : x0 + 4, by + kBarHeight - 4, without_drone(b.text, name),
                std::string("font-size=\"11\" fill=\"#222222\"") + (b.label_left ? " text-anchor=\"end\"" : ""));
    out << "</g>\n";
  }
  for (const ConditionMark& m : conditions) draw_condition(out, m, rt + m.lane * kConditionLane, until);
  out << "</g>\n";
}

/// A row per drone in `shown` (every drone of a small fleet); waits, arrows and failsafes of
/// the drones shown. Returns the y below the panel.
double timeline(std::ostream& out, const RunResult& run, const std::vector<TraceEvent>& events, double top,
                double until, const std::vector<int>& shown, bool summary) {
  std::vector<std::vector<Bar>> bars = bars_of(run, events, until);
  std::vector<std::vector<ConditionMark>> conditions;
  std::vector<int> condition_lanes = condition_marks(run, events, until, conditions);
  std::vector<Wait> waits = waits_of(run, events);
  RowGeometry rows = row_geometry(run, bars, conditions, condition_lanes, waits, shown, top, until);
  rows.summary = summary;
  double bottom = shown.empty() ? top : rows.bottom(shown.back());
  time_axis(out, top, bottom, until);
  for (int d : shown) draw_row(out, run, d, bars[d], conditions[d], rows, until);
  draw_failsafes(out, run, failsafes_of(run, events, until), rows, until);
  draw_waits(out, run, waits, rows, until);
  return bottom + 58;
}

/// The altitude panel's vertical scale: from the lowest to 10 % above the highest sample.
struct AltitudeFrame {
  double lo = 0, hi = 1, top = 0, bottom = 0;
  double to_y(double z) const { return bottom - (z - lo) / (hi - lo) * kAltitudeHeight; }
};

// ---- large fleets: a summary instead of a row per drone --------------------------------

constexpr std::size_t kManyDrones = kPlotSummaryAbove;
constexpr std::size_t kDetailRows = 10;  ///< rows of their own in the summary view
constexpr int kColumns = 410;            ///< time columns of the summary's bands (2 px each)
constexpr double kBandHeight = 150;      ///< the state band's plot area, px
constexpr double kNever = 1e300;

/// What one drone of a large fleet did: when it failed (its first failed action or
/// failsafe), when its last action ended (all ended), and when it was flying an action.
struct DroneCourse {
  double failed = kNever, failed_action = kNever, done = kNever, last_end = 0;
  std::vector<std::pair<double, double>> busy;  ///< its actions' spans, overlaps merged
  double busy_time() const {
    double sum = 0;
    for (auto [from, to] : busy) sum += to - from;
    return sum;
  }
};

std::vector<DroneCourse> courses_of(const std::vector<std::vector<Bar>>& bars,
                                    const std::vector<FailsafePhase>& failsafes) {
  std::vector<DroneCourse> out(bars.size());
  for (std::size_t d = 0; d < bars.size(); ++d) {
    DroneCourse& c = out[d];
    bool open = false;
    for (const Bar& b : bars[d]) {  // in the order they started
      if (!c.busy.empty() && b.start <= c.busy.back().second) c.busy.back().second = std::max(c.busy.back().second, b.end);
      else c.busy.push_back({b.start, b.end});
      open = open || b.outcome.empty();
      c.last_end = std::max(c.last_end, b.end);
      if (b.outcome == "failed") c.failed_action = std::min(c.failed_action, b.end);
    }
    c.failed = c.failed_action;
    if (!bars[d].empty() && !open) c.done = c.last_end;
  }
  for (const FailsafePhase& f : failsafes) out[f.drone].failed = std::min(out[f.drone].failed, f.from);
  return out;
}

/// The drones that get a row of their own: those whose action failed, then those that
/// finished last (of those ending together, the longest in flight), at most kDetailRows,
/// in fleet order.
std::vector<int> detail_rows(const std::vector<DroneCourse>& courses) {
  std::vector<int> order(courses.size());
  for (std::size_t d = 0; d < order.size(); ++d) order[d] = static_cast<int>(d);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    bool fa = courses[a].failed_action < kNever, fb = courses[b].failed_action < kNever;
    if (fa != fb) return fa;
    // Drones that end together (at a last barrier): the one that flew longest held it up.
    if (std::abs(courses[a].last_end - courses[b].last_end) > 1e-6) return courses[a].last_end > courses[b].last_end;
    return courses[a].busy_time() > courses[b].busy_time();
  });
  order.resize(std::min(order.size(), kDetailRows));
  std::sort(order.begin(), order.end());
  return order;
}

/// The first column whose end is at or after t (a column counts the states at its end, so
/// the last one shows how the run ended).
int column_of(double t, double until) {
  if (t >= kNever) return kColumns;
  return std::clamp(static_cast<int>(std::ceil(t / until * kColumns - 1)), 0, kColumns);
}

enum State { kFlying, kWaiting, kDone, kFailed, kStates };

/// How many drones are in each state at the end of each column: flying an action, waiting
/// (before, between or for others), done (every action ended), failed or in failsafe.
std::vector<std::vector<int>> state_counts(const std::vector<DroneCourse>& courses, double until) {
  std::vector<std::vector<int>> diff(kStates, std::vector<int>(kColumns + 1, 0));
  auto add = [&](State s, double from, double to) {
    int a = column_of(from, until), b = column_of(to, until);
    if (a < b) ++diff[s][a], --diff[s][b];
  };
  for (const DroneCourse& c : courses) {
    double stop = std::min(c.failed, c.done);
    for (auto [from, to] : c.busy) add(kFlying, from, std::min(to, stop));
    if (c.failed < kNever) add(kFailed, c.failed, kNever);
    else if (c.done < kNever) add(kDone, c.done, kNever);
  }
  std::vector<std::vector<int>> counts(kStates, std::vector<int>(kColumns, 0));
  for (int s : {kFlying, kDone, kFailed})
    for (int k = 0, run = 0; k < kColumns; ++k) counts[s][k] = run += diff[s][k];
  for (int k = 0; k < kColumns; ++k)
    counts[kWaiting][k] = static_cast<int>(courses.size()) - counts[kFlying][k] - counts[kDone][k] - counts[kFailed][k];
  return counts;
}

double column_x(int k) { return kLeft + k * (kRight - kLeft) / kColumns; }

/// A stacked area between the `lower` and `upper` counts, step by step over the columns.
std::string band_path(const std::vector<int>& lower, const std::vector<int>& upper, double bottom, double per_drone) {
  auto y = [&](int v) { return num(bottom - v * per_drone); };
  std::string p = "M" + num(column_x(0)) + "," + y(upper[0]);
  for (int k = 0; k < kColumns; ++k) {
    if (k > 0 && upper[k] != upper[k - 1]) p += "V" + y(upper[k]);
    p += "H" + num(column_x(k + 1));
  }
  p += "V" + y(lower[kColumns - 1]);
  for (int k = kColumns - 1; k >= 0; --k) {
    if (k < kColumns - 1 && lower[k] != lower[k + 1]) p += "V" + y(lower[k]);
    p += "H" + num(column_x(k));
  }
  return p + "Z";
}

const char* kStateNames[kStates] = {"flying an action", "waiting", "done", "failed or in failsafe"};
const char* kStateKeys[kStates] = {"flying", "waiting", "done", "failed"};
const char* kStateColours[kStates] = {"#56B4E9", "#E69F00", "#009E73", "#D55E00"};

/// The band's areas, flying at the bottom; each says its peak and its count per column.
void state_areas(std::ostream& out, const std::vector<std::vector<int>>& counts, double bottom, double per_drone,
                 double until) {
  std::vector<int> lower(kColumns, 0);
  for (int s = 0; s < kStates; ++s) {
    std::vector<int> upper(kColumns);
    for (int k = 0; k < kColumns; ++k) upper[k] = lower[k] + counts[s][k];
    auto peak = std::max_element(counts[s].begin(), counts[s].end());
    std::string per_column;
    for (int c : counts[s]) per_column += (per_column.empty() ? "" : " ") + std::to_string(c);
    out << "<path class=\"state\" data-state=\"" << kStateKeys[s] << "\" data-peak=\"" << *peak
        << "\" data-counts=\"" << per_column << "\" d=\"" << band_path(lower, upper, bottom, per_drone) << "\" fill=\""
        << kStateColours[s] << "\" fill-opacity=\"0.55\" stroke=\"none\"><title>" << kStateNames[s] << ": up to " << *peak
        << " drones (at " << num((peak - counts[s].begin() + 1.0) * until / kColumns) << " s)</title></path>\n";
    lower = upper;
  }
}

/// How many drones were in each state over mission time, stacked. Returns the y below it.
double state_band(std::ostream& out, const std::vector<DroneCourse>& courses, double top, double until) {
  const double bottom = top + kBandHeight, n = static_cast<double>(courses.size());
  time_axis(out, top, bottom, until);
  out << "<g class=\"state-band\" data-drones=\"" << courses.size() << "\" data-columns=\"" << kColumns << "\">\n";
  state_areas(out, state_counts(courses, until), bottom, kBandHeight / n, until);
  out << "<rect x=\"" << num(kLeft) << "\" y=\"" << num(top) << "\" width=\"" << num(kRight - kLeft) << "\" height=\""
      << num(kBandHeight) << "\" fill=\"none\" stroke=\"#888888\"/>\n";
  for (double v : {0.0, n / 2, n})
    out << text(kLeft - 7, bottom - v / n * kBandHeight + 4, num(v, 0), "text-anchor=\"end\" font-size=\"11\" fill=\"#444444\"");
  out << text(kLeft - 45, top + kBandHeight / 2, "drones",
              "text-anchor=\"middle\" font-size=\"11\" fill=\"#444444\" transform=\"rotate(-90 " + num(kLeft - 45) + " " +
                  num(top + kBandHeight / 2) + ")\"");
  double x = kLeft, y = bottom + 52;
  for (int s = 0; s < kStates; ++s) {
    out << "<rect x=\"" << num(x) << "\" y=\"" << num(y - 10) << "\" width=\"22\" height=\"12\" fill=\"" << kStateColours[s]
        << "\" fill-opacity=\"0.55\"/>\n";
    out << text(x + 28, y, kStateNames[s], "font-size=\"11\" fill=\"#222222\"");
    x += 28 + std::string(kStateNames[s]).size() * kCharWidth + 18;
  }
  out << "</g>\n";
  return y + 30;
}

/// A large fleet's heights: the band from the lowest to the highest drone and the median,
/// per time column (each drone's height held from one sample to the next).
void altitude_spread(std::ostream& out, const RunResult& run, const AltitudeFrame& f, double until) {
  std::vector<std::vector<double>> heights(kColumns);
  for (const DroneSummary& d : run.drones) {
    if (d.track.empty()) continue;
    std::size_t k = 0;
    for (int c = 0; c < kColumns; ++c) {
      double t = (c + 0.5) * until / kColumns;
      while (k + 1 < d.track.size() && d.track[k + 1].t <= t) ++k;
      heights[c].push_back(d.track[k].z);
    }
  }
  if (heights[0].empty()) return;
  std::string top, bottom, median;
  for (int c = 0; c < kColumns; ++c) {
    std::vector<double>& h = heights[c];
    auto [lo, hi] = std::minmax_element(h.begin(), h.end());
    double low = *lo, high = *hi;
    std::nth_element(h.begin(), h.begin() + static_cast<long>(h.size() / 2), h.end());
    std::string x0 = num(column_x(c)), x1 = num(column_x(c + 1));
    top += " " + x0 + "," + num(f.to_y(high)) + " " + x1 + "," + num(f.to_y(high));
    bottom = " " + x1 + "," + num(f.to_y(low)) + " " + x0 + "," + num(f.to_y(low)) + bottom;
    median += (median.empty() ? "" : " ") + num((column_x(c) + column_x(c + 1)) / 2) + "," + num(f.to_y(h[h.size() / 2]));
  }
  out << "<polygon class=\"altitude-range\" points=\"" << top.substr(1) << bottom << "\" fill=\"#0072B2\" "
      << "fill-opacity=\"0.15\" stroke=\"#0072B2\" stroke-opacity=\"0.4\" stroke-width=\"0.6\"><title>lowest to "
      << "highest of " << run.drones.size() << " drones</title></polygon>\n";
  out << "<polyline class=\"altitude-median\" points=\"" << median << "\" fill=\"none\" stroke=\"#0072B2\" "
      << "stroke-width=\"1.5\" stroke-dasharray=\"6 3\"><title>median height</title></polyline>\n";
}

AltitudeFrame altitude_axes(std::ostream& out, const RunResult& run, double top, double until) {
  AltitudeFrame f;
  for (const auto& d : run.drones)
    for (const Sample& s : d.track) f.lo = std::min(f.lo, s.z), f.hi = std::max(f.hi, s.z);
  f.hi += 0.1 * (f.hi - f.lo);
  f.top = top;
  f.bottom = top + kAltitudeHeight;
  double step = nice_step(f.hi - f.lo, 5);
  out << "<g class=\"altitude-axes\" font-size=\"11\" fill=\"#444444\">\n";
  for (double z = std::ceil(f.lo / step) * step; z <= f.hi + 1e-9; z += step) {
    out << "<line x1=\"" << num(kLeft - 4) << "\" y1=\"" << num(f.to_y(z)) << "\" x2=\"" << num(kRight) << "\" y2=\""
        << num(f.to_y(z)) << "\" stroke=\"" << (std::abs(z) < 1e-9 ? "#cccccc" : "#eeeeee") << "\"/>\n";
    out << text(kLeft - 7, f.to_y(z) + 4, num(z), "text-anchor=\"end\"");
  }
  double tstep = nice_step(until, 12);
  for (double t = 0; t <= until + 1e-9; t += tstep)
    out << text(time_x(t, until), f.bottom + 14, num(t), "text-anchor=\"middle\"");
  out << text(kLeft - 45, (top + f.bottom) / 2, "z (m, up)",
              "text-anchor=\"middle\" transform=\"rotate(-90 " + num(kLeft - 45) + " " + num((top + f.bottom) / 2) + ")\"");
  out << "<rect x=\"" << num(kLeft) << "\" y=\"" << num(top) << "\" width=\"" << num(kRight - kLeft) << "\" height=\""
      << num(kAltitudeHeight) << "\" fill=\"none\" stroke=\"#888888\"/>\n</g>\n";
  return f;
}

/// One drone's height over time in its colour; its failsafe's part dashed red over it.
void altitude_line(std::ostream& out, const RunResult& run, std::size_t d, const std::vector<FailsafePhase>& failsafes,
                   const AltitudeFrame& f, double until) {
  const std::vector<Sample>& track = run.drones[d].track;
  if (track.empty()) return;
  // Heights hold between samples (one per change): a step at each, the last held to the end.
  auto points = [&](double from) {
    std::string p;
    for (std::size_t k = 0; k < track.size(); ++k) {
      if (track[k].t < from && (k + 1 < track.size() && track[k + 1].t <= from)) continue;
      double t = std::max(track[k].t, from);
      p += (p.empty() ? "" : " ") + num(time_x(t, until)) + "," + num(f.to_y(track[k].z));
    }
    return p + " " + num(time_x(until, until)) + "," + num(f.to_y(track.back().z));
  };
  out << "<polyline class=\"altitude\" data-drone=\"" << xml(run.drones[d].name) << "\" points=\"" << points(0)
      << "\" fill=\"none\" stroke=\"" << drone_colour(static_cast<int>(d)) << "\" stroke-width=\"2\" stroke-linejoin=\"round\"/>\n";
  for (const FailsafePhase& p : failsafes)
    if (p.drone == static_cast<int>(d))
      out << "<polyline class=\"altitude-failsafe\" data-drone=\"" << xml(run.drones[d].name) << "\" points=\""
          << points(p.from) << "\" fill=\"none\" stroke=\"" << kFailsafe << "\" stroke-width=\"2\" stroke-dasharray=\"5 3\"/>\n";
}

/// The altitude panel: the `shown` drones' heights over mission time, on the timeline's time
/// axis (every drone of a small fleet; a large one's spread is altitude_spread's). Returns
/// the y below it.
double altitude(std::ostream& out, const RunResult& run, const std::vector<FailsafePhase>& failsafes, double top,
                double until, const std::vector<int>& shown, bool summary) {
  AltitudeFrame f = altitude_axes(out, run, top, until);
  if (summary) altitude_spread(out, run, f, until);
  for (int d : shown) altitude_line(out, run, static_cast<std::size_t>(d), failsafes, f, until);
  return f.bottom + 20;
}

void timeline_legend(std::ostream& out, double y) {
  double x = kLeft;
  out << "<g class=\"legend\" font-size=\"11\" fill=\"#222222\">\n";
  for (const char* o : {"succeeded", "preempted", "cancelled", "failed", "running at the end"}) {
    const char* c = outcome_colour(o);
    out << "<rect x=\"" << num(x) << "\" y=\"" << num(y - 10) << "\" width=\"22\" height=\"12\" rx=\"2\" fill=\"" << c
        << "\" fill-opacity=\"0.3\" stroke=\"" << c << "\"/>\n";
    out << text(x + 28, y, o);
    x += 28 + std::string(o).size() * kCharWidth + 18;
  }
  for (bool v : {true, false}) {
    out << "<path d=\"M" << num(x) << "," << num(y - 9) << " l8,0 l-4,7 z\" fill=\"" << (v ? "#009E73" : "#D55E00")
        << "\"/>\n";
    std::string label = v ? "condition true" : "condition false";
    out << text(x + 14, y, label);
    x += 14 + label.size() * kCharWidth + 18;
  }
  // Second line: what crosses between drones, and the failsafe.
  x = kLeft;
  y += 18;
  out << "<line x1=\"" << num(x) << "\" y1=\"" << num(y - 4) << "\" x2=\"" << num(x + 22) << "\" y2=\"" << num(y - 4)
      << "\" stroke=\"" << kWait << "\" stroke-width=\"2\" stroke-dasharray=\"2 2\"/>\n";
  out << text(x + 28, y, "waited for another drone's trigger (arrow: from the sender, when it sent)");
  x += 28 + 72 * kCharWidth;
  out << "<rect x=\"" << num(x) << "\" y=\"" << num(y - 10) << "\" width=\"22\" height=\"12\" fill=\"url(#failsafe-hatch)\" stroke=\""
      << kFailsafe << "\" stroke-dasharray=\"3 2\"/>\n";
  out << text(x + 28, y, "failsafe");
  out << "</g>\n";
}

void map_marks(std::ostream& out, const MapFrame& f, const std::vector<PlotMark>& marks) {
  if (marks.empty()) return;
  out << "<g class=\"violations\" fill=\"none\" stroke=\"#d62728\" stroke-width=\"2\">\n";
  for (const PlotMark& m : marks) {
    double px = f.to_x(m.x), py = f.to_y(m.y);
    out << "<circle data-violation=\"" << xml(m.label) << "\" cx=\"" << num(px) << "\" cy=\"" << num(py)
        << "\" r=\"9\"/>\n";
    out << text(px + 12, py - 8, m.label + " " + num(m.t) + " s", "fill=\"#d62728\" stroke=\"none\" font-size=\"11\"");
  }
  out << "</g>\n";
}

/// Separation kept in flight: an orange ring where a drone gave way (title: to whom, how far
/// apart) and a dot where it flew on, at its position then in its track.
void map_give_ways(std::ostream& out, const MapFrame& f, const RunResult& run, const std::vector<TraceEvent>& events) {
  out << "<g class=\"give-ways\" stroke=\"#ff8c00\" stroke-width=\"2\">\n";
  std::unordered_map<std::string, const DroneSummary*> by_name;
  for (const DroneSummary& s : run.drones) by_name[s.name] = &s;
  for (const TraceEvent& e : events) {
    if (e.event != "give_way" && e.event != "resume") continue;
    auto found = by_name.find(e.drone);
    const DroneSummary* d = found == by_name.end() ? nullptr : found->second;
    if (!d || d->track.empty()) continue;
    // The last sample at or before the event (samples are in time order).
    auto after = std::upper_bound(d->track.begin(), d->track.end(), e.t,
                                  [](double t, const Sample& s) { return t < s.t; });
    const Sample* at = after == d->track.begin() ? &d->track.front() : &*(after - 1);
    const bool gave = e.event == "give_way";
    out << "<circle class=\"" << (gave ? "give-way" : "resume") << "\" data-drone=\"" << xml(e.drone)
        << "\" data-other=\"" << xml(e.other) << "\" cx=\"" << num(f.to_x(at->x)) << "\" cy=\"" << num(f.to_y(at->y))
        << "\" r=\"" << (gave ? 8 : 3) << "\" fill=\"" << (gave ? "none" : "#ff8c00") << "\"><title>" << xml(e.drone)
        << (gave ? " gives way to " : " flies on after ") << xml(e.other) << " at " << num(e.t) << " s"
        << (e.distance ? ", " + num(*e.distance) + " m apart" : "") << "</title></circle>\n";
  }
  out << "</g>\n";
}

void timeline_marks(std::ostream& out, const std::vector<PlotMark>& marks, double top, double bottom, double until) {
  if (marks.empty()) return;
  out << "<g class=\"violation-times\" stroke=\"#d62728\" stroke-width=\"1.5\">\n";
  for (const PlotMark& m : marks) {
    double px = time_x(m.t, until);
    out << "<line data-violation=\"" << xml(m.label) << "\" x1=\"" << num(px) << "\" y1=\"" << num(top)
        << "\" x2=\"" << num(px) << "\" y2=\"" << num(bottom) << "\"/>\n";
  }
  out << "</g>\n";
}

/// Which drones get a row, a named track and an altitude line: all of a small fleet; of a
/// large one (the summary view) those whose action failed or that finished last.
struct View {
  bool summary = false;
  std::vector<int> shown;
  std::vector<bool> named;  ///< per drone: in `shown`
  std::vector<DroneCourse> courses;
};

View view_of(const RunResult& run, const std::vector<TraceEvent>& events, double until) {
  View v;
  v.summary = run.drones.size() > kManyDrones;
  if (v.summary) {
    v.courses = courses_of(bars_of(run, events, until), failsafes_of(run, events, until));
    v.shown = detail_rows(v.courses);
  } else {
    for (std::size_t d = 0; d < run.drones.size(); ++d) v.shown.push_back(static_cast<int>(d));
  }
  v.named.assign(run.drones.size(), false);
  for (int d : v.shown) v.named[d] = true;
  return v;
}

/// The tracks seen from above; returns the y below the panel.
double map_panel(std::ostream& body, const RunResult& run, const std::vector<TraceEvent>& events,
                 const std::vector<PlotMark>& marks, const View& view, double y) {
  body << text(kLeft - 100, y, "Tracks seen from above", "font-size=\"13\" font-weight=\"bold\" fill=\"#444444\"");
  y += 12;
  MapFrame frame = map_frame(run, y);
  map_axes(body, frame);
  std::vector<std::vector<const TraceEvent*>> failsafes = per_drone(run, events, "failsafe");
  for (std::size_t d = 0; d < run.drones.size(); ++d) {
    std::vector<double> failsafe_from;
    for (const TraceEvent* e : failsafes[d]) failsafe_from.push_back(e->t);
    if (view.summary) map_thin_track(body, frame, run.drones[d], static_cast<int>(d), failsafe_from, view.named[d]);
    else map_track(body, frame, run.drones[d], static_cast<int>(d), failsafe_from);
  }
  map_marks(body, frame, marks);
  map_give_ways(body, frame, run, events);
  if (view.summary) map_legend_many(body, run, frame.top);
  else map_legend(body, run, frame.top);
  return frame.bottom + 64;
}

std::string panel_title(double y, const std::string& title) {
  return text(kLeft - 100, y, title, "font-size=\"13\" font-weight=\"bold\" fill=\"#444444\"");
}

/// Altitude, then (a large fleet's) states over time, then the action rows; returns the y below.
double time_panels(std::ostream& body, const RunResult& run, const std::vector<TraceEvent>& events,
                   const std::vector<PlotMark>& marks, const View& view, double y, double until) {
  body << panel_title(y, view.summary ? "Altitude over time: every drone's range and median; the drones named below"
                                      : "Altitude over time");
  y += 12;
  y = altitude(body, run, failsafes_of(run, events, until), y, until, view.shown, view.summary) + 24;
  if (view.summary) {
    body << panel_title(y, "Drones in each state over time (" + std::to_string(run.drones.size()) + " drones)");
    y = state_band(body, view.courses, y + 12, until);
    body << panel_title(y, "Actions over time: the drones that failed or finished last (" +
                               std::to_string(view.shown.size()) + " of " + std::to_string(run.drones.size()) + ")");
  } else {
    body << panel_title(y, "Actions over time");
  }
  y += 12;
  double timeline_top = y;
  y = timeline(body, run, events, y, until, view.shown, view.summary);
  timeline_marks(body, marks, timeline_top, y, until);
  timeline_legend(body, y);
  return y + 34;
}

}  // namespace

std::string plot_svg(const RunResult& run, const std::vector<TraceEvent>& events, const std::vector<PlotMark>& marks,
                     const std::string& caption) {
  std::ostringstream body;
  double y = 20;
  std::string status = run.completed ? "completed in " + num(run.duration) + " s"
                                     : "failed" + (run.error.empty() ? std::string() : ": " + run.error);
  body << text(kLeft - 100, y, "Mission run — " + status, "font-size=\"15\" font-weight=\"bold\" fill=\"#222222\"");
  y += 26;
  if (!caption.empty()) {
    body << text(kLeft - 100, y - 6, caption, "class=\"caption\" font-size=\"12\" fill=\"#d62728\"");
    y += 14;
  }
  double until = run.duration;
  for (const TraceEvent& e : events) until = std::max(until, e.t);
  if (until <= 0) until = 1;
  View view = view_of(run, events, until);
  y = map_panel(body, run, events, marks, view, y);
  y = time_panels(body, run, events, marks, view, y, until);

  std::ostringstream out;
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << num(kWidth) << "\" height=\"" << num(y)
      << "\" viewBox=\"0 0 " << num(kWidth) << " " << num(y) << "\" font-family=\"" << kFont << "\">\n";
  out << "<defs>\n<marker id=\"arrow\" viewBox=\"0 0 10 10\" refX=\"9\" refY=\"5\" markerWidth=\"7\" markerHeight=\"7\" "
         "orient=\"auto-start-reverse\"><path d=\"M0,0 L10,5 L0,10 z\" fill=\""
      << kWait << "\"/></marker>\n<pattern id=\"failsafe-hatch\" width=\"6\" height=\"6\" patternUnits=\"userSpaceOnUse\" "
         "patternTransform=\"rotate(45)\"><rect width=\"6\" height=\"6\" fill=\"#D62728\" fill-opacity=\"0.06\"/>"
         "<line x1=\"0\" y1=\"0\" x2=\"0\" y2=\"6\" stroke=\"#D62728\" stroke-opacity=\"0.45\" stroke-width=\"1.5\"/></pattern>\n</defs>\n";
  out << "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n";
  out << body.str();
  out << "</svg>\n";
  return out.str();
}

}  // namespace eamos::trace
