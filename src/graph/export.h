#pragma once
// Graph output for people and tools: Graphviz DOT (rendered to SVG by `dot`) and JSON,
// for the AMT, the MEG and each drone's MDG, plus node/arc statistics.
#include <string>

#include <nlohmann/json.hpp>

#include "graph/pipeline.h"

namespace eamos::graph {

std::string amt_dot(const Compilation& c);
std::string meg_dot(const Compilation& c);
std::string mdg_dot(const Compilation& c, int drone);

nlohmann::json amt_json(const Compilation& c);
nlohmann::json meg_json(const Compilation& c);
nlohmann::json mdg_json(const Compilation& c, int drone);
nlohmann::json stats_json(const Compilation& c);

/// An expression as JSON: {"num":3}, {"bool":true}, {"prop":"X","drone":"Drone1"},
/// {"op":">=","args":[…]} — what a DEX evaluates, so no parser is needed onboard.
nlohmann::json expr_json(const lang::Expr& e, const lang::Mission& m);
/// One MEG node with everything needed to execute it (kind, drone, args, condition…).
nlohmann::json meg_node_json(const Compilation& c, const MegNode& n);
/// Short human label: "Drone1.Takeoff(3)", "If Drone1.Sensor1() >= 100", "fork PAR_x".
std::string meg_node_label(const Compilation& c, const MegNode& n);
/// meg_node_label appended to `out`: a writer labelling every node reuses one string.
void append_meg_node_label(std::string& out, const Compilation& c, const MegNode& n);

}  // namespace eamos::graph
