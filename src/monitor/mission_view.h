#pragma once
// What the page needs to know about a mission besides its events: the drones (home,
// geofence), the mission text, the MEG's nodes and arcs (to place each event on its node and
// to draw who triggered whom) and the MEG and MDG pictures in the layout `eamos graph` draws.
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "graph/pipeline.h"

namespace eamos::monitor {

/// Renders Graphviz DOT to SVG; false with `error` set (the CLI's `dot` runner).
using SvgRenderer = std::function<bool(const std::string& dot, std::string& svg, std::string& error)>;

struct ViewInput {
  std::string mission_name;  ///< the file name the page shows
  std::string fleet_text;    ///< the fleet YAML, "" for none
  bool live = false;         ///< a running mission (else a replay)
};

/// The mission as JSON for the page. Graphs larger than the page can draw are left out
/// (with "graph_note" saying so); `warnings` collects renderer failures.
nlohmann::json mission_view(const graph::Compilation& c, const ViewInput& in, const SvgRenderer& render,
                            std::string& warnings);

/// Without a mission to compile (an old trace without a header): the page draws lanes only.
nlohmann::json bare_view(const ViewInput& in, const std::string& why);

}  // namespace eamos::monitor
