// Every drone's dex::Mission straight from the compiled graphs, for one process that
// compiled the mission itself (`eamos run`, `eamos verify`): no text to write, hash and
// parse back. It holds exactly what the mission file gives the reader, member for member
// (the file's members are mission_writer.cpp's; tests/deploy/mission_memory_test.cpp
// compares the two structures), and ends with the reader's own last step, dex::link_mission.
#include <map>

#include "deploy/mission_file.h"
#include "graph/export.h"
#include "lang/ast.h"

namespace eamos::deploy {

namespace {

/// The settings a mission file carries: not the priority (the fleet's `priorities` are)
/// nor where in the fleet file a limit was set.
fleet::DroneSettings file_settings(const fleet::DroneSettings& s) {
  fleet::DroneSettings out = s;
  out.priority = 0;
  if (out.site.geofence) out.site.geofence->max_altitude_at.reset();
  return out;
}

/// The capabilities a mission file carries: names, arities, classes and value types.
fleet::DroneType file_type(const fleet::DroneType& t) {
  fleet::DroneType out;
  out.generic = false;
  out.name = t.name;
  out.adapter = t.adapter;
  out.sensors = t.sensors;
  for (const fleet::ActionSpec& a : t.actions)
    out.actions.push_back({.name = a.name, .arities = a.arities, .action_class = a.action_class});
  for (const fleet::PropertySpec& p : t.properties) out.properties.push_back({.name = p.name, .type = p.type});
  return out;
}

class Builder {
 public:
  Builder(const graph::Compilation& c, std::vector<std::string>& errors) : c_(c), errors_(errors) {
    std::vector<std::string> names;
    for (int d = 0; d < c.drone_count(); ++d) {
      tables_.index.emplace(c.drone_name(d), d);
      names.push_back(c.drone_name(d));
    }
    tables_.fleet = dex::SharedTable<std::vector<std::string>>(std::move(names));
    bool any = false;
    for (const fleet::DroneSettings& s : c.settings) any |= s.priority > 0;
    if (!any) return;  // the file leaves `priorities` out: declaration order
    std::vector<int> priorities;
    for (std::size_t d = 0; d < c.settings.size(); ++d)
      priorities.push_back(c.settings[d].priority > 0 ? c.settings[d].priority : static_cast<int>(d) + 1);
    tables_.priorities = dex::SharedTable<std::vector<int>>(std::move(priorities));
  }

  bool mission(int drone, const std::string& hash, dex::Mission& m) {
    const graph::Mdg& g = c_.mdgs[drone];
    where_ = c_.drone_name(drone) + "/mission.json";
    m = dex::Mission{};
    m.hash = hash;
    m.source = c_.source->path;
    m.self = drone;
    m.fleet = tables_.fleet;
    m.settings = file_settings(c_.settings[drone]);
    m.type = file_type(c_.checked.drone_types[drone]);
    m.reads = g.reads;
    m.separation = c_.fleet.safety.min_separation;
    m.priorities = tables_.priorities;
    for (const std::vector<int>& set : g.drone_sets) m.drone_sets.push_back(shared_set(set));
    m.nodes.resize(g.nodes.size());
    bool ok = true;
    for (std::size_t i = 0; i < g.nodes.size(); ++i) ok &= node(g.nodes[i], g.cancels(static_cast<int>(i)), m.nodes[i]);
    m.arcs.reserve(g.arcs.size());
    for (const graph::MdgArc& a : g.arcs) m.arcs.push_back({a.from, a.to, a.kind, a.branch});
    if (ok && dex::link_mission(m).empty()) return true;
    if (ok) fail("a node of the compiled MDG is there twice");
    m = dex::Mission{};
    return false;
  }

 private:
  /// Each drone set once per process, as FleetTables shares the sets the files' reads expand.
  dex::SharedTable<std::vector<int>> shared_set(const std::vector<int>& set) {
    auto [it, added] = tables_.sets.try_emplace(graph::drone_ranges(set));
    if (added) it->second = dex::SharedTable<std::vector<int>>(set);
    return it->second;
  }

  bool node(const graph::MdgNode& mn, std::span<const int> cancels, dex::Node& n) {
    const graph::MegNode& meg = c_.meg.nodes[mn.meg];
    n.meg = mn.meg;
    n.drone = mn.drone;
    n.internal = mn.internal;
    n.kind = meg.kind;
    n.name = meg.name;
    n.text = meg.name;
    n.line = static_cast<int>(meg.loc.line);
    n.col = static_cast<int>(meg.loc.col);
    n.scope = meg.scope >= 0 ? meg.scope : -1;
    n.waits = mn.waits;
    n.notify = mn.notify;
    bool ok = true;
    if (meg.kind == graph::MegKind::action) {
      n.text = graph::meg_node_label(c_, meg);
      n.args.resize(meg.args.size());
      for (std::size_t i = 0; i < meg.args.size(); ++i) ok &= expr(*meg.args[i], n.args[i]);
    } else if (meg.kind == graph::MegKind::condition) {
      n.text = lang::expr_text(*meg.condition);
      n.control = meg.control;
      if (meg.control == lang::ControlKind::RepeatFor) n.count = meg.count;
      n.cancels.assign(cancels.begin(), cancels.end());
      ok &= expr(*meg.condition, n.condition);
    } else if (meg.kind == graph::MegKind::pause) {
      n.seconds = meg.seconds;
    }
    return ok;
  }

  bool expr(const lang::Expr& e, dex::Expr& out) {
    switch (e.kind) {
      case lang::ExprKind::number: out.kind = dex::Expr::Kind::number, out.number = e.number; return true;
      case lang::ExprKind::boolean: out.kind = dex::Expr::Kind::boolean, out.boolean = e.boolean; return true;
      case lang::ExprKind::property: {
        out.kind = dex::Expr::Kind::property;
        out.property = std::string(e.property);
        auto it = tables_.index.find(std::string(e.drone));
        if (it != tables_.index.end()) return out.drone = it->second, true;
        return fail("a property of drone \"" + std::string(e.drone) + "\", which is not in the fleet");
      }
      case lang::ExprKind::unary:
      case lang::ExprKind::binary: {
        out.kind = e.kind == lang::ExprKind::unary ? dex::Expr::Kind::unary : dex::Expr::Kind::binary;
        out.op = lang::op_text(e.op);
        out.args.resize(e.kind == lang::ExprKind::unary ? 1 : 2);
        bool ok = expr(*e.lhs, out.args[0]);
        return e.kind == lang::ExprKind::unary ? ok : expr(*e.rhs, out.args[1]) && ok;
      }
      case lang::ExprKind::name: break;
    }
    return fail("a block name where a value belongs");
  }

  bool fail(const std::string& what) {
    errors_.push_back(where_ + ": error: the compiled mission holds " + what +
                      "; this is a defect of eamos (please report it with the mission)");
    return false;
  }

  const graph::Compilation& c_;
  std::vector<std::string>& errors_;
  FleetTables tables_;
  std::string where_;
};

}  // namespace

bool compiled_missions(const graph::Compilation& c, std::vector<dex::Mission>& out,
                       std::vector<std::string>& errors) {
  const std::string hash = mission_hash(c);
  out.assign(c.drone_count(), dex::Mission{});
  Builder build(c, errors);
  for (int d = 0; d < c.drone_count(); ++d)
    if (!build.mission(d, hash, out[d])) return false;
  return true;
}

}  // namespace eamos::deploy
