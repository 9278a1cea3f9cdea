#include "dex/mission.h"

#include <fstream>

namespace eamos::dex {

int Mission::find(int meg, int drone) const {
  auto it = index.find({meg, drone});
  return it == index.end() ? -1 : it->second;
}

namespace {

using nlohmann::json;

bool kind_from(const std::string& s, graph::MegKind& k) {
  for (graph::MegKind c : {graph::MegKind::init, graph::MegKind::action, graph::MegKind::fork,
                           graph::MegKind::condition, graph::MegKind::terminal, graph::MegKind::pause,
                           graph::MegKind::end})
    if (s == graph::meg_kind_name(c)) return k = c, true;
  return false;
}

bool arc_kind_from(const std::string& s, graph::ArcKind& k) {
  for (graph::ArcKind c : {graph::ArcKind::exec, graph::ArcKind::back, graph::ArcKind::partner, graph::ArcKind::stop})
    if (s == graph::arc_kind_name(c)) return k = c, true;
  return false;
}

bool branch_from(const std::string& s, graph::Branch& b) {
  for (graph::Branch c : {graph::Branch::any, graph::Branch::true_, graph::Branch::false_, graph::Branch::go,
                          graph::Branch::repeat, graph::Branch::exit, graph::Branch::do_, graph::Branch::skip,
                          graph::Branch::done, graph::Branch::continue_})
    if (s == graph::branch_name(c)) return b = c, true;
  return false;
}

int fleet_index(const std::vector<std::string>& fleet, const std::string& name) {
  for (std::size_t i = 0; i < fleet.size(); ++i)
    if (fleet[i] == name) return static_cast<int>(i);
  return -1;
}

fleet::Vec3 vec3(const json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

void load_settings(const json& d, fleet::DroneSettings& s) {
  s.name = d.at("name").get<std::string>();
  s.type = d.at("type").get<std::string>();
  s.adapter = d.at("adapter").get<std::string>();
  s.home = vec3(d.at("home"));
  s.battery_percent = d.at("battery").get<double>();
  std::string failsafe = d.at("failsafe").get<std::string>();
  s.failsafe = failsafe == "return_home" ? fleet::Failsafe::return_home
               : failsafe == "hover"     ? fleet::Failsafe::hover
                                         : fleet::Failsafe::land;
  const json& l = d.at("limits");
  s.limits.max_speed_mps = l.at("max_speed").get<double>();
  s.limits.max_climb_mps = l.at("max_climb").get<double>();
  s.limits.max_descent_mps = l.at("max_descent").get<double>();
  s.limits.max_accel_mps2 = l.at("max_accel").get<double>();
  s.limits.max_altitude_m = l.at("max_altitude").get<double>();
  for (const auto& [name, model] : d.at("sensors").items())
    s.sensors[name] = {model.at("value").get<double>(), vec3(model.at("gradient"))};
  for (const auto& [name, t] : d.at("timeouts").items()) s.timeouts_s[name] = t.get<double>();
  if (d.contains("connection")) s.connection = d["connection"].get<std::string>();
  if (d.contains("sysid")) s.sysid = d["sysid"].get<int>();
}

void load_type(const json& t, fleet::DroneType& type) {
  type.name = t.at("name").get<std::string>();
  type.adapter = t.at("adapter").get<std::string>();
  type.sensors = t.at("sensors").get<int>();
  type.generic = false;
  for (const auto& a : t.at("actions")) {
    fleet::ActionSpec spec;
    spec.name = a.at("name").get<std::string>();
    spec.arities = a.at("arities").get<std::vector<int>>();
    std::string k = a.at("class").get<std::string>();
    spec.action_class = k == "payload" ? fleet::ActionClass::payload
                        : k == "system" ? fleet::ActionClass::system
                                        : fleet::ActionClass::motion;
    type.actions.push_back(spec);
  }
  for (const auto& p : t.at("properties")) {
    fleet::PropertySpec spec;
    spec.name = p.at("name").get<std::string>();
    spec.type = p.at("type").get<std::string>() == "boolean" ? fleet::ValueType::boolean : fleet::ValueType::number;
    type.properties.push_back(spec);
  }
}

bool load_node(const json& j, Mission& m, Node& n, std::string& error) {
  n.meg = j.at("meg").get<int>();
  n.drone = fleet_index(m.fleet, j.at("drone").get<std::string>());
  if (n.drone < 0) return error = "node held by unknown drone", false;
  n.internal = j.at("internal").get<bool>();
  if (!kind_from(j.at("kind").get<std::string>(), n.kind)) return error = "unknown node kind", false;
  n.name = j.value("name", "");
  n.text = j.value("text", n.name);
  n.line = j.value("line", 0);
  n.col = j.value("col", 0);
  if (j.contains("args"))
    for (const auto& a : j["args"]) {
      Expr e;
      if (!parse_expr(a, m.fleet, e, error)) return false;
      n.args.push_back(std::move(e));
    }
  if (n.kind == graph::MegKind::condition) {
    if (!parse_expr(j.at("condition"), m.fleet, n.condition, error)) return false;
    collect_drones(n.condition, n.condition_reads);
    n.control = lang::control_from_name(j.at("control").get<std::string>());
    if (n.control == lang::ControlKind::none) return error = "unknown control structure", false;
    n.count = j.value("count", 0LL);
  }
  n.seconds = j.value("seconds", 0.0);
  n.scope = j.value("scope", -1);
  if (j.contains("cancels")) n.cancels = j["cancels"].get<std::vector<int>>();
  return true;
}

}  // namespace

bool load_mission(const json& file, Mission& m, std::string& error) {
  try {
    if (file.value("format", "") != "eamos-mission")
      return error = "not an eamos mission file (format is not \"eamos-mission\")", false;
    int version = file.value("format_version", 0);
    if (version != 1)
      return error = "mission file format version " + std::to_string(version) +
                     " is not supported by this DEX (knows 1); recompile with a matching eamos", false;
    m.hash = file.at("mission_hash").get<std::string>();
    m.source = file.at("source").value("path", "");
    m.fleet = file.at("fleet").get<std::vector<std::string>>();
    load_settings(file.at("drone"), m.settings);
    load_type(file.at("type"), m.type);
    m.self = fleet_index(m.fleet, m.settings.name);
    if (m.self < 0) return error = "the drone is not in the mission's fleet", false;
    for (const auto& r : file.at("reads")) m.reads.push_back(fleet_index(m.fleet, r.get<std::string>()));
    for (const auto& j : file.at("nodes")) {
      Node n;
      if (!load_node(j, m, n, error)) {
        error = "node " + std::to_string(m.nodes.size()) + ": " + error;
        return false;
      }
      m.index[{n.meg, n.drone}] = static_cast<int>(m.nodes.size());
      m.nodes.push_back(std::move(n));
    }
    int count = static_cast<int>(m.nodes.size());
    for (const auto& j : file.at("arcs")) {
      Arc a;
      a.from = j.at("from").get<int>();
      a.to = j.at("to").get<int>();
      if (a.from < 0 || a.from >= count || a.to < 0 || a.to >= count) return error = "arc to a missing node", false;
      if (!arc_kind_from(j.at("kind").get<std::string>(), a.kind)) return error = "unknown arc kind", false;
      if (!branch_from(j.value("branch", ""), a.branch)) return error = "unknown branch", false;
      m.nodes[a.from].out.push_back(static_cast<int>(m.arcs.size()));
      if (a.kind == graph::ArcKind::exec) ++m.nodes[a.to].exec_in;
      if (a.kind == graph::ArcKind::back) ++m.nodes[a.to].back_in;
      m.arcs.push_back(a);
    }
    for (const Node& n : m.nodes)
      for (int c : n.cancels)
        if (c < 0 || c >= count) return error = "cancel of a missing node", false;
  } catch (const json::exception& e) {
    error = std::string("malformed mission file: ") + e.what();
    return false;
  }
  return true;
}

bool load_mission_file(const std::string& path, Mission& out, std::string& error) {
  std::ifstream in(path);
  if (!in) return error = "cannot read '" + path + "'", false;
  json j = json::parse(in, nullptr, false);
  if (j.is_discarded()) return error = "'" + path + "' is not valid JSON", false;
  if (!load_mission(j, out, error)) return error = path + ": " + error, false;
  return true;
}

}  // namespace eamos::dex
