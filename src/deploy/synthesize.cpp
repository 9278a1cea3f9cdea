#include "deploy/synthesize.h"

#include <filesystem>
#include <fstream>

#include "graph/export.h"
#include "version.h"

namespace eamos::deploy {

using nlohmann::json;

namespace {

json vec3(const fleet::Vec3& v) { return json::array({v.x, v.y, v.z}); }

json limits_json(const fleet::Limits& l) {
  return {{"max_speed", l.max_speed_mps}, {"max_climb", l.max_climb_mps},
          {"max_descent", l.max_descent_mps}, {"max_accel", l.max_accel_mps2},
          {"max_altitude", l.max_altitude_m}};
}

json settings_json(const fleet::DroneSettings& s, int index) {
  json sensors = json::object();
  for (const auto& [name, model] : s.sensors)
    sensors[name] = {{"value", model.base}, {"gradient", vec3(model.gradient)}};
  json j = {{"name", s.name},
            {"index", index},
            {"type", s.type},
            {"adapter", s.adapter},
            {"home", vec3(s.home)},
            {"battery", s.battery_percent},
            {"failsafe", fleet::failsafe_name(s.failsafe)},
            {"limits", limits_json(s.limits)},
            {"sensors", sensors},
            {"timeouts", s.timeouts_s}};
  if (!s.connection.empty()) j["connection"] = s.connection;
  if (s.sysid > 0) j["sysid"] = s.sysid;
  return j;
}

json type_json(const fleet::DroneType& t) {
  json actions = json::array();
  for (const auto& a : t.actions)
    actions.push_back({{"name", a.name}, {"arities", a.arities}, {"class", fleet::action_class_name(a.action_class)}});
  json props = json::array();
  for (const auto& p : t.properties)
    props.push_back({{"name", p.name}, {"type", p.type == fleet::ValueType::boolean ? "boolean" : "number"}});
  return {{"name", t.name}, {"adapter", t.adapter}, {"sensors", t.sensors},
          {"actions", actions}, {"properties", props}};
}

}  // namespace

json drone_mission(const graph::Compilation& c, int drone, const std::string& hash) {
  json fleet_names = json::array();
  for (int d = 0; d < c.drone_count(); ++d) fleet_names.push_back(c.drone_name(d));
  json mdg = graph::mdg_json(c, drone);
  return {{"format", "eamos-mission"},
          {"format_version", kMissionFormatVersion},
          {"compiler", std::string("eamos ") + EAMOS_VERSION},
          {"mission_hash", hash},
          {"source", {{"path", c.source->path}, {"package", c.mission.package}}},
          {"drone", settings_json(c.settings[drone], drone)},
          {"type", type_json(c.checked.drone_types[drone])},
          {"fleet", fleet_names},
          {"reads", mdg["reads"]},
          {"nodes", std::move(mdg["nodes"])},
          {"arcs", std::move(mdg["arcs"])}};
}

json manifest(const graph::Compilation& c, const std::string& hash) {
  json drones = json::array();
  for (int d = 0; d < c.drone_count(); ++d)
    drones.push_back({{"name", c.drone_name(d)},
                      {"type", c.settings[d].type},
                      {"adapter", c.settings[d].adapter},
                      {"folder", c.drone_name(d)},
                      {"mission", c.drone_name(d) + "/mission.json"}});
  return {{"format", "eamos-deployment"},
          {"format_version", kMissionFormatVersion},
          {"compiler", std::string("eamos ") + EAMOS_VERSION},
          {"mission_hash", hash},
          {"source", c.source->path},
          {"drones", drones}};
}

namespace {

bool cannot_write(const std::filesystem::path& path, Diagnostics& diags) {
  diags.error(nullptr, {}, "cannot write '" + path.string() + "'; check the output folder's permissions");
  return false;
}

bool write_text(const std::filesystem::path& path, const std::string& text, Diagnostics& diags) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  return out ? true : cannot_write(path, diags);
}

}  // namespace

bool write_deployment(const graph::Compilation& c, const std::string& dir, Diagnostics& diags) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) {
    diags.error(nullptr, {}, "cannot create output folder '" + dir + "': " + ec.message());
    return false;
  }
  std::string hash = mission_hash(c);
  if (!write_text(fs::path(dir) / "manifest.json", manifest(c, hash).dump(2) + "\n", diags)) return false;
  for (int d = 0; d < c.drone_count(); ++d) {
    fs::path folder = fs::path(dir) / c.drone_name(d);
    fs::create_directories(folder, ec);
    if (ec) {
      diags.error(nullptr, {}, "cannot create '" + folder.string() + "': " + ec.message());
      return false;
    }
    // Streamed straight into the file: no drone's mission is ever held in memory.
    fs::path file = folder / "mission.json";
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    bool written = out && write_drone_mission(out, c, d, hash);
    out << "\n";
    out.close();
    if (!written || !out) return cannot_write(file, diags);
  }
  return true;
}

}  // namespace eamos::deploy
