#include <map>

#include "graph/export.h"

namespace eamos::graph {

using nlohmann::json;

json expr_json(const lang::Expr& e, const lang::Mission& m) {
  switch (e.kind) {
    case lang::ExprKind::number: return {{"num", e.number}};
    case lang::ExprKind::boolean: return {{"bool", e.boolean}};
    case lang::ExprKind::property: {
      json j = {{"prop", e.property}, {"drone", e.drone}};
      (void)m;
      return j;
    }
    case lang::ExprKind::name: return {{"name", e.drone}};
    case lang::ExprKind::unary: return {{"op", lang::op_text(e.op)}, {"args", {expr_json(*e.lhs, m)}}};
    case lang::ExprKind::binary:
      return {{"op", lang::op_text(e.op)}, {"args", {expr_json(*e.lhs, m), expr_json(*e.rhs, m)}}};
  }
  return nullptr;
}

namespace {
json drone_list(const Compilation& c, const std::vector<int>& drones) {
  json out = json::array();
  for (int d : drones) out.push_back(c.drone_name(d));
  return out;
}
}  // namespace

json meg_node_json(const Compilation& c, const MegNode& n) {
  json j = {{"id", n.id}, {"kind", meg_kind_name(n.kind)}, {"name", n.name},
            {"line", n.loc.line}, {"col", n.loc.col}};
  if (n.drone >= 0) j["drone"] = c.drone_name(n.drone);
  if (n.kind == MegKind::action) {
    json args = json::array();
    for (const lang::Expr* a : n.args) args.push_back(expr_json(*a, c.mission));
    j["args"] = args;
    j["text"] = meg_node_label(c, n);
  }
  if (n.kind == MegKind::condition) {
    j["control"] = lang::control_name(n.control);
    j["condition"] = expr_json(*n.condition, c.mission);
    j["text"] = lang::expr_text(*n.condition);
    if (n.control == lang::ControlKind::RepeatFor) j["count"] = n.count;
    j["terminals"] = c.meg.terminals(n.id);
    if (std::span<const int> cancels = c.meg.cancels(n.id); !cancels.empty()) j["cancels"] = cancels;
  }
  if (!n.reads.empty()) j["reads"] = drone_list(c, n.reads);
  if (n.kind == MegKind::terminal) {
    j["condition"] = n.owner_condition;
    if (n.role != Role::none) j["role"] = role_name(n.role);
  }
  if (n.kind == MegKind::pause) j["seconds"] = n.seconds;
  if (n.scope >= 0) j["scope"] = n.scope;
  return j;
}

namespace {
json arc_json(int from, int to, ArcKind kind, Branch branch) {
  json a = {{"from", from}, {"to", to}, {"kind", arc_kind_name(kind)}};
  if (branch != Branch::any) a["branch"] = branch_name(branch);
  return a;
}
}  // namespace

json amt_json(const Compilation& c) {
  json nodes = json::array();
  for (const AmtNode& n : c.amt.nodes) {
    json j = {{"id", n.id}, {"kind", amt_kind_name(n.kind)}, {"name", n.name},
              {"line", n.loc.line}, {"col", n.loc.col}, {"children", n.children}};
    if (n.parent >= 0) j["parent"] = n.parent;
    if (n.role != Role::none) j["role"] = role_name(n.role);
    if (n.drone >= 0) j["drone"] = c.drone_name(n.drone);
    if (n.kind == AmtKind::action) {
      json args = json::array();
      for (const lang::Expr* a : n.args) args.push_back(expr_json(*a, c.mission));
      j["args"] = args;
    }
    if (n.condition) j["condition"] = expr_json(*n.condition, c.mission);
    if (n.control == lang::ControlKind::RepeatFor) j["count"] = n.count;
    if (n.kind == AmtKind::pause) j["seconds"] = n.seconds;
    nodes.push_back(std::move(j));
  }
  return {{"graph", "amt"}, {"root", c.amt.root()}, {"nodes", nodes}};
}

json meg_json(const Compilation& c) {
  json nodes = json::array();
  for (const MegNode& n : c.meg.nodes) nodes.push_back(meg_node_json(c, n));
  json arcs = json::array();
  for (const MegArc& a : c.meg.arcs) arcs.push_back(arc_json(a.from, a.to, a.kind, a.branch));
  json drones = json::array();
  for (int d = 0; d < c.drone_count(); ++d) drones.push_back(c.drone_name(d));
  return {{"graph", "meg"}, {"drones", drones}, {"init", c.meg.init}, {"end", c.meg.end},
          {"nodes", nodes}, {"arcs", arcs}};
}

namespace {
/// Each sorted drone set as [first, last] index ranges, as mission files write them.
json drone_sets_json(const std::vector<std::vector<int>>& sets) {
  json all = json::array();
  for (const std::vector<int>& set : sets) {
    json ranges = json::array();
    for (auto [first, last] : graph::drone_ranges(set)) ranges.push_back({first, last});
    all.push_back(std::move(ranges));
  }
  return all;
}
}  // namespace

json mdg_json(const Compilation& c, int drone) {
  const Mdg& g = c.mdgs[drone];
  json nodes = json::array();
  for (std::size_t i = 0; i < g.nodes.size(); ++i) {
    const MdgNode& mn = g.nodes[i];
    const MegNode& n = c.meg.nodes[mn.meg];
    json j = meg_node_json(c, n);
    j["index"] = i;
    j["meg"] = mn.meg;
    j.erase("id");
    j["drone"] = c.drone_name(mn.drone);
    j["internal"] = mn.internal;
    if (is_sync_point(n.kind)) j["clone"] = true;
    if (mn.waits >= 0) j["waits"] = mn.waits;
    if (mn.notify >= 0) j["notify"] = mn.notify;
    if (n.kind == MegKind::condition) j["evaluated_by"] = c.drone_name(n.drone);
    j.erase("terminals");
    j.erase("cancels");
    if (std::span<const int> cancels = g.cancels(static_cast<int>(i)); !cancels.empty()) j["cancels"] = cancels;
    if (n.kind == MegKind::terminal) {
      int ci = n.owner_condition >= 0 ? g.find(n.owner_condition, c.meg.nodes[n.owner_condition].drone) : -1;
      if (ci >= 0) j["condition"] = ci;
      else j.erase("condition");
    }
    nodes.push_back(std::move(j));
  }
  json arcs = json::array();
  for (const MdgArc& a : g.arcs) {
    json j = arc_json(a.from, a.to, a.kind, a.branch);
    j["external"] = g.external(a);
    arcs.push_back(std::move(j));
  }
  return {{"graph", "mdg"}, {"drone", c.drone_name(drone)}, {"reads", drone_list(c, g.reads)},
          {"drone_sets", drone_sets_json(g.drone_sets)}, {"nodes", nodes}, {"arcs", arcs}};
}

json stats_json(const Compilation& c) {
  std::map<std::string, int> amt_kinds, meg_kinds;
  std::size_t amt_arcs = 0;
  for (const AmtNode& n : c.amt.nodes) {
    ++amt_kinds[amt_kind_name(n.kind)];
    amt_arcs += n.children.size();
  }
  for (const MegNode& n : c.meg.nodes) ++meg_kinds[meg_kind_name(n.kind)];
  json mdgs = json::object();
  std::size_t total_nodes = 0, total_arcs = 0;
  for (int d = 0; d < c.drone_count(); ++d) {
    const Mdg& g = c.mdgs[d];
    std::size_t internal = g.internal_count(), external_arcs = 0;
    for (const MdgArc& a : g.arcs) external_arcs += g.external(a) ? 1 : 0;
    mdgs[c.drone_name(d)] = {{"nodes", g.nodes.size()},
                             {"internal_nodes", internal},
                             {"external_nodes", g.nodes.size() - internal},
                             {"arcs", g.arcs.size()},
                             {"external_arcs", external_arcs}};
    total_nodes += g.nodes.size();
    total_arcs += g.arcs.size();
  }
  return {{"mission", c.source ? c.source->path : ""},
          {"drones", c.drone_count()},
          {"amt", {{"nodes", c.amt.nodes.size()}, {"arcs", amt_arcs}, {"by_kind", amt_kinds}}},
          {"meg", {{"nodes", c.meg.nodes.size()}, {"arcs", c.meg.arcs.size()}, {"by_kind", meg_kinds}}},
          {"mdg", {{"nodes", total_nodes}, {"arcs", total_arcs}, {"per_drone", mdgs}}}};
}

}  // namespace eamos::graph
