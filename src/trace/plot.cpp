#include "trace/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <tuple>

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
  for (std::size_t d = 0; d < run.drones.size(); ++d) {
    std::vector<std::vector<std::pair<double, double>>> used;
    for (const TraceEvent& e : events) {
      if (e.event != "condition" || e.drone != run.drones[d].name) continue;
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

/// A message that drone `m.from` only passed on: it arrived there at the instant it was
/// sent on, before any action of that drone ended then (a terminal or fork the drone holds
/// relayed another drone's trigger). Returns the index of the message it passed on, or -1.
long relayed_from(const std::vector<TraceEvent>& events, std::size_t k, const std::string& sender) {
  const TraceEvent& m = events[k];
  long found = -1;
  for (std::size_t j = k; j-- > 0;) {
    const TraceEvent& e = events[j];
    if (std::abs(e.t - m.sent) > 1e-6) break;  // events are in time order
    if (e.drone == sender && e.event == "end") return -1;  // its own action ended then: its own trigger
    if (e.event == "message" && e.to == m.from && e.kind == "trigger" && found < 0) found = static_cast<long>(j);
  }
  return found;
}

/// The waits in `events`: a `trigger` message that arrived at t at a drone that started an
/// action at t, after it had been idle since earlier (a wait of at least 50 ms): since its
/// last action ended or it last sent a trigger of its own (a condition it holds ran). A
/// trigger relayed through another drone's terminal is counted from where it came from.
std::vector<Wait> waits_of(const RunResult& run, const std::vector<TraceEvent>& events) {
  std::vector<Wait> waits;
  for (std::size_t i = 0; i < events.size(); ++i) {
    const TraceEvent& m = events[i];
    if (m.event != "message" || m.kind != "trigger" || m.to < 0 || m.to >= static_cast<int>(run.drones.size())) continue;
    if (m.from < 0 || m.from >= static_cast<int>(run.drones.size())) continue;
    const std::string& receiver = run.drones[m.to].name;
    bool starts = std::any_of(events.begin() + i, events.end(), [&](const TraceEvent& e) {
      return e.drone == receiver && e.event == "start" && std::abs(e.t - m.t) < 1e-6;
    });
    if (!starts) continue;
    double busy_until = -1;
    for (std::size_t k = 0; k < i; ++k) {
      const TraceEvent& e = events[k];
      if (e.drone == receiver && e.event == "end") busy_until = std::max(busy_until, e.t);
      if (e.event == "message" && e.from == m.to && relayed_from(events, k, receiver) < 0)
        busy_until = std::max(busy_until, e.sent);
    }
    if (busy_until < 0 || m.t - busy_until < 0.05) continue;
    std::size_t origin = i;
    for (long r; (r = relayed_from(events, origin, run.drones[events[origin].from].name)) >= 0;) {
      origin = static_cast<std::size_t>(r);
      if (events[origin].from < 0 || events[origin].from >= static_cast<int>(run.drones.size())) break;
    }
    int on = events[origin].from;
    if (on < 0 || on >= static_cast<int>(run.drones.size()) || on == m.to) continue;
    auto same = std::find_if(waits.begin(), waits.end(), [&](const Wait& w) { return w.drone == m.to && w.until == m.t; });
    if (same == waits.end()) {
      waits.push_back({m.to, busy_until, m.t, {}, {}});
      same = waits.end() - 1;
    }
    if (std::find(same->on.begin(), same->on.end(), on) == same->on.end()) {
      same->on.push_back(on);
      same->sent.push_back(events[origin].sent);
    }
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
  double bottom(std::size_t d) const { return bars_top[d] + lanes[d] * kLaneHeight + 6 + extra[d]; }
  double middle(std::size_t d) const { return (bars_top[d] + bottom(d)) / 2; }
};

void draw_failsafes(std::ostream& out, const RunResult& run, const std::vector<FailsafePhase>& phases,
                    const RowGeometry& rows, double until) {
  for (const FailsafePhase& f : phases) {
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
    std::string on;
    for (int s : w.on) on += (on.empty() ? "" : ", ") + run.drones[s].name;
    std::string seconds = num(w.until - w.from);
    double x0 = time_x(w.from, until), x1 = time_x(w.until, until);
    double y = rows.bars_top[w.drone] + rows.lanes[w.drone] * kLaneHeight + 15;
    out << "<g class=\"wait\" data-drone=\"" << xml(run.drones[w.drone].name) << "\" data-on=\"" << xml(on)
        << "\" data-seconds=\"" << seconds << "\"><title>" << xml(run.drones[w.drone].name) << " waited " << seconds
        << " s on " << xml(on) << " (" << num(w.from) << "–" << num(w.until) << " s)</title>\n";
    out << "<line x1=\"" << num(x0) << "\" y1=\"" << num(y) << "\" x2=\"" << num(x1) << "\" y2=\"" << num(y)
        << "\" stroke=\"" << kWait << "\" stroke-width=\"2\" stroke-dasharray=\"2 2\"/>\n";
    for (std::size_t k = 0; k < w.on.size(); ++k) {
      double sx = time_x(w.sent[k], until), sy = rows.middle(w.on[k]);
      double ty = rows.middle(w.drone) + (rows.middle(w.drone) > sy ? -6 : 6);
      out << "<line class=\"trigger\" x1=\"" << num(sx) << "\" y1=\"" << num(sy) << "\" x2=\"" << num(x1)
          << "\" y2=\"" << num(ty) << "\" stroke=\"" << kWait << "\" stroke-width=\"1.3\" marker-end=\"url(#arrow)\"/>\n";
    }
    // The label sits on the dotted bar, inside it when it fits, else left of its end.
    std::string label = "waits " + seconds + " s on " + on;
    bool fits = x1 - x0 > label.size() * kCharWidth * 0.85 + 6;
    out << text(fits ? x0 + 3 : x1 - 3, y - 3, label,
                std::string("font-size=\"9.5\" fill=\"") + kWait + "\"" + (fits ? "" : " text-anchor=\"end\""));
    out << "</g>\n";
  }
}

/// The timeline's time axis: a grid line from `top` to `bottom` at each step, labelled below.
void draw_time_axis(std::ostream& out, double top, double bottom, double until) {
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

/// Returns the y below the panel.
double timeline(std::ostream& out, const RunResult& run, const std::vector<TraceEvent>& events, double top,
                double until) {
  std::vector<std::vector<Bar>> bars = bars_of(run, events, until);
  std::vector<std::vector<ConditionMark>> conditions;
  std::vector<int> condition_lanes = condition_marks(run, events, until, conditions);
  std::vector<Wait> waits = waits_of(run, events);
  RowGeometry rows;
  double y = top;
  for (std::size_t d = 0; d < run.drones.size(); ++d) {
    rows.lanes.push_back(pack_lanes(bars[d], run.drones[d].name, until));
    rows.top.push_back(y);
    double strip = conditions[d].empty() ? kTickStrip : condition_lanes[d] * kConditionLane + 2;
    rows.bars_top.push_back(y + strip);
    bool waited = std::any_of(waits.begin(), waits.end(), [&](const Wait& w) { return w.drone == static_cast<int>(d); });
    rows.extra.push_back(waited ? 16 : 0);
    y = rows.bottom(d);
  }
  double bottom = y;
  draw_time_axis(out, top, bottom, until);
  for (std::size_t d = 0; d < run.drones.size(); ++d) {
    const std::string& name = run.drones[d].name;
    double rt = rows.top[d];
    double rb = rows.bottom(d);
    out << "<g class=\"row\" data-drone=\"" << xml(name) << "\">\n";
    out << "<line x1=\"" << num(kLeft - 100) << "\" y1=\"" << num(rb) << "\" x2=\"" << num(kRight) << "\" y2=\""
        << num(rb) << "\" stroke=\"#cccccc\"/>\n";
    out << text(kLeft - 10, (rt + rb) / 2 + 4, name,
                std::string("text-anchor=\"end\" font-size=\"12\" font-weight=\"bold\" fill=\"") +
                    drone_colour(static_cast<int>(d)) + "\"");
    for (const Bar& b : bars[d]) {
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
    for (const ConditionMark& m : conditions[d]) draw_condition(out, m, rt + m.lane * kConditionLane, until);
    out << "</g>\n";
  }
  draw_failsafes(out, run, failsafes_of(run, events, until), rows, until);
  draw_waits(out, run, waits, rows, until);
  return bottom + 58;
}

/// The altitude panel: every drone's height over mission time, on the timeline's time
/// axis; a failsafe's part of it dashed red over the drone's colour. Returns the y below it.
double altitude(std::ostream& out, const RunResult& run, const std::vector<FailsafePhase>& failsafes, double top,
                double until) {
  double lo = 0, hi = 1;
  for (const auto& d : run.drones)
    for (const Sample& s : d.track) lo = std::min(lo, s.z), hi = std::max(hi, s.z);
  hi += 0.1 * (hi - lo);
  double bottom = top + kAltitudeHeight;
  auto to_y = [&](double z) { return bottom - (z - lo) / (hi - lo) * kAltitudeHeight; };
  double step = nice_step(hi - lo, 5);
  out << "<g class=\"altitude-axes\" font-size=\"11\" fill=\"#444444\">\n";
  for (double z = std::ceil(lo / step) * step; z <= hi + 1e-9; z += step) {
    out << "<line x1=\"" << num(kLeft - 4) << "\" y1=\"" << num(to_y(z)) << "\" x2=\"" << num(kRight) << "\" y2=\""
        << num(to_y(z)) << "\" stroke=\"" << (std::abs(z) < 1e-9 ? "#cccccc" : "#eeeeee") << "\"/>\n";
    out << text(kLeft - 7, to_y(z) + 4, num(z), "text-anchor=\"end\"");
  }
  double tstep = nice_step(until, 12);
  for (double t = 0; t <= until + 1e-9; t += tstep) out << text(time_x(t, until), bottom + 14, num(t), "text-anchor=\"middle\"");
  out << text(kLeft - 45, (top + bottom) / 2, "z (m, up)",
              "text-anchor=\"middle\" transform=\"rotate(-90 " + num(kLeft - 45) + " " + num((top + bottom) / 2) + ")\"");
  out << "<rect x=\"" << num(kLeft) << "\" y=\"" << num(top) << "\" width=\"" << num(kRight - kLeft) << "\" height=\""
      << num(kAltitudeHeight) << "\" fill=\"none\" stroke=\"#888888\"/>\n</g>\n";
  for (std::size_t d = 0; d < run.drones.size(); ++d) {
    const std::vector<Sample>& track = run.drones[d].track;
    if (track.empty()) continue;
    // Heights hold between samples (one per change): a step at each, the last held to the end.
    auto points = [&](double from) {
      std::string p;
      for (std::size_t k = 0; k < track.size(); ++k) {
        if (track[k].t < from && (k + 1 < track.size() && track[k + 1].t <= from)) continue;
        double t = std::max(track[k].t, from);
        p += (p.empty() ? "" : " ") + num(time_x(t, until)) + "," + num(to_y(track[k].z));
      }
      return p + " " + num(time_x(until, until)) + "," + num(to_y(track.back().z));
    };
    out << "<polyline class=\"altitude\" data-drone=\"" << xml(run.drones[d].name) << "\" points=\"" << points(0)
        << "\" fill=\"none\" stroke=\"" << drone_colour(static_cast<int>(d)) << "\" stroke-width=\"2\" stroke-linejoin=\"round\"/>\n";
    for (const FailsafePhase& f : failsafes)
      if (f.drone == static_cast<int>(d))
        out << "<polyline class=\"altitude-failsafe\" data-drone=\"" << xml(run.drones[d].name) << "\" points=\""
            << points(f.from) << "\" fill=\"none\" stroke=\"" << kFailsafe << "\" stroke-width=\"2\" stroke-dasharray=\"5 3\"/>\n";
  }
  return bottom + 20;
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
  for (const TraceEvent& e : events) {
    if (e.event != "give_way" && e.event != "resume") continue;
    const DroneSummary* d = nullptr;
    for (const DroneSummary& s : run.drones) d = s.name == e.drone ? &s : d;
    if (!d || d->track.empty()) continue;
    const Sample* at = &d->track.front();
    for (const Sample& s : d->track) at = s.t <= e.t ? &s : at;
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
  body << text(kLeft - 100, y, "Tracks seen from above", "font-size=\"13\" font-weight=\"bold\" fill=\"#444444\"");
  y += 12;
  MapFrame frame = map_frame(run, y);
  map_axes(body, frame);
  for (std::size_t d = 0; d < run.drones.size(); ++d) {
    std::vector<double> failsafe_from;
    for (const TraceEvent& e : events)
      if (e.event == "failsafe" && e.drone == run.drones[d].name) failsafe_from.push_back(e.t);
    map_track(body, frame, run.drones[d], static_cast<int>(d), failsafe_from);
  }
  map_marks(body, frame, marks);
  map_give_ways(body, frame, run, events);
  map_legend(body, run, frame.top);
  y = frame.bottom + 64;

  double until = run.duration;
  for (const TraceEvent& e : events) until = std::max(until, e.t);
  if (until <= 0) until = 1;
  body << text(kLeft - 100, y, "Altitude over time", "font-size=\"13\" font-weight=\"bold\" fill=\"#444444\"");
  y += 12;
  y = altitude(body, run, failsafes_of(run, events, until), y, until) + 24;
  body << text(kLeft - 100, y, "Actions over time", "font-size=\"13\" font-weight=\"bold\" fill=\"#444444\"");
  y += 12;
  double timeline_top = y;
  y = timeline(body, run, events, y, until);
  timeline_marks(body, marks, timeline_top, y, until);
  timeline_legend(body, y);
  y += 34;

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
