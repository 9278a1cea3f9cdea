#include "monitor/mission_view.h"

#include <algorithm>

#include "graph/export.h"
#include "graph/palette.h"

namespace eamos::monitor {

namespace {

// Beyond these `dot` takes longer than a person waits, and the picture is unreadable anyway.
constexpr std::size_t max_graph_nodes = 1500;
constexpr int max_mdg_pictures = 24;
// The page's drone colours come from here (graph/palette.h), never from a rule of its own. A
// replay without a mission learns its drones from the events, so colours for at least this
// many are sent; past them (such a replay of more drones) the page repeats them.
constexpr int min_palette = 256;

nlohmann::json drone_json(const graph::Compilation& c, int d) {
  const fleet::DroneSettings& s = c.settings[d];
  nlohmann::json j = {{"name", c.drone_name(d)}, {"index", d}, {"type", s.type},
                      {"home", {s.home.x, s.home.y, s.home.z}}};
  if (const fleet::Geofence* g = c.fleet.geofence_for(c.drone_name(d))) {
    nlohmann::json fence = {{"polygon", nlohmann::json::array()}};
    for (const auto& [x, y] : g->polygon) fence["polygon"].push_back({x, y});
    if (g->min_altitude_m) fence["min_altitude"] = *g->min_altitude_m;
    if (g->max_altitude_m) fence["max_altitude"] = *g->max_altitude_m;
    j["geofence"] = fence;
  }
  return j;
}

nlohmann::json nodes_json(const graph::Compilation& c) {
  nlohmann::json nodes = nlohmann::json::array();
  for (const graph::MegNode& n : c.meg.nodes)
    nodes.push_back({{"id", n.id}, {"kind", graph::meg_kind_name(n.kind)},
                     {"drone", n.drone >= 0 ? c.drone_name(n.drone) : ""}, {"name", n.name},
                     {"line", n.loc.line}, {"label", graph::meg_node_label(c, n)}});
  return nodes;
}

nlohmann::json arcs_json(const graph::Compilation& c) {
  nlohmann::json arcs = nlohmann::json::array();
  for (const graph::MegArc& a : c.meg.arcs)
    arcs.push_back({{"from", a.from}, {"to", a.to}, {"kind", graph::arc_kind_name(a.kind)},
                    {"branch", graph::branch_name(a.branch)}});
  return arcs;
}

// One picture: its SVG and, for an MDG, which MEG node (and holder) each "mN" id is.
bool add_graph(nlohmann::json& graphs, const std::string& name, const std::string& dot, nlohmann::json map,
               const SvgRenderer& render, std::string& warnings) {
  std::string svg, error;
  if (!render(dot, svg, error)) {
    warnings += "the monitor shows no graphs: " + error + "\n";
    return false;
  }
  nlohmann::json g = {{"name", name}, {"svg", svg}};
  if (!map.is_null()) g["mdg_nodes"] = std::move(map);
  graphs.push_back(std::move(g));
  return true;
}

nlohmann::json graphs_json(const graph::Compilation& c, const SvgRenderer& render, std::string& note,
                           std::string& warnings) {
  nlohmann::json graphs = nlohmann::json::array();
  if (c.meg.nodes.size() > max_graph_nodes) {
    note = "the MEG has " + std::to_string(c.meg.nodes.size()) + " nodes, more than the page draws (" +
           std::to_string(max_graph_nodes) + "); `eamos graph` writes it";
    return graphs;
  }
  if (!add_graph(graphs, "MEG", graph::meg_dot(c), nullptr, render, warnings)) return graphs;
  for (int d = 0; d < c.drone_count() && d < max_mdg_pictures; ++d) {
    nlohmann::json map = nlohmann::json::array();
    for (const graph::MdgNode& n : c.mdgs[d].nodes) map.push_back({n.meg, c.drone_name(n.drone)});
    if (!add_graph(graphs, "MDG " + c.drone_name(d), graph::mdg_dot(c, d), std::move(map), render, warnings))
      break;
  }
  if (c.drone_count() > max_mdg_pictures)
    note = "MDG pictures of the first " + std::to_string(max_mdg_pictures) + " drones only";
  return graphs;
}

}  // namespace

nlohmann::json mission_view(const graph::Compilation& c, const ViewInput& in, const SvgRenderer& render,
                            std::string& warnings) {
  nlohmann::json j;
  j["mission"] = in.mission_name;
  j["live"] = in.live;
  j["source"] = c.source ? c.source->text : "";
  j["fleet"] = in.fleet_text;
  j["drones"] = nlohmann::json::array();
  for (int d = 0; d < c.drone_count(); ++d) j["drones"].push_back(drone_json(c, d));
  j["palette"] = graph::drone_palette(std::max(c.drone_count(), min_palette));
  j["nodes"] = nodes_json(c);
  j["arcs"] = arcs_json(c);
  std::string note;
  j["graphs"] = graphs_json(c, render, note, warnings);
  if (!note.empty()) j["graph_note"] = note;
  return j;
}

nlohmann::json bare_view(const ViewInput& in, const std::string& why) {
  return {{"mission", in.mission_name}, {"live", in.live}, {"source", ""}, {"fleet", in.fleet_text},
          {"drones", nlohmann::json::array()}, {"nodes", nlohmann::json::array()},
          {"arcs", nlohmann::json::array()}, {"graphs", nlohmann::json::array()}, {"graph_note", why},
          {"palette", graph::drone_palette(min_palette)}};
}

}  // namespace eamos::monitor
