#include "deploy/manifest.h"

#include <nlohmann/json.hpp>

#include "diag/file_read.h"

namespace eamos::deploy {

using nlohmann::json;

namespace {

bool one_name_inside(const std::string& folder) {
  return !folder.empty() && folder != "." && folder != ".." && folder.find('/') == std::string::npos &&
         folder.find('\0') == std::string::npos;
}

bool read_drones(const json& list, const std::string& file, DeploymentManifest& out, std::string& error) {
  for (const json& d : list) {
    if (!d.is_object() || !d.contains("name") || !d["name"].is_string() || !d.contains("folder") ||
        !d["folder"].is_string()) {
      error = file + ": drone " + std::to_string(out.drones.size() + 1) +
              " has no name or folder; compile the deployment again";
      return false;
    }
    std::string folder = d["folder"].get<std::string>();
    if (!one_name_inside(folder)) {
      error = file + ": the folder '" + folder + "' of " + d["name"].get<std::string>() +
              " is not a folder inside the deployment; compile the deployment again";
      return false;
    }
    out.drones.push_back({d["name"].get<std::string>(), folder});
  }
  return true;
}

}  // namespace

bool read_manifest(const std::string& dir, DeploymentManifest& out, std::string& error) {
  out = {};
  std::string file = dir + "/manifest.json", text;
  diag::FileRead r = diag::read_bounded_file(file, kMaxManifestBytes, text);
  if (r.status != diag::FileRead::ok) {
    error = "cannot read " + file + " (" + diag::describe(r, kMaxManifestBytes) + "); is '" + dir +
            "' a folder written by `eamos compile -o`?";
    return false;
  }
  json m = json::parse(text, nullptr, false);
  if (!m.is_object() || m.value("format", json()) != "eamos-deployment" || !m.contains("mission_hash") ||
      !m["mission_hash"].is_string() || !m.contains("drones") || !m["drones"].is_array()) {
    error = file + " is not an eamos deployment manifest; compile the deployment again";
    return false;
  }
  out.mission_hash = m["mission_hash"].get<std::string>();
  if (m.contains("source") && m["source"].is_string()) out.source = m["source"].get<std::string>();
  if (!read_drones(m["drones"], file, out, error)) return false;
  if (out.drones.empty()) {
    error = file + " lists no drones; compile the deployment again";
    return false;
  }
  return true;
}

}  // namespace eamos::deploy
