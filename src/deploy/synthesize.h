#pragma once
// Mission synthesis and deployment (paper, sections IV.D–E). The paper generates Go
// source per drone and compiles it; eamos writes one self-contained, versioned data file
// per drone that a single generic DEX loads (docs/architecture.md says why).
#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include "diag/diagnostics.h"
#include "graph/pipeline.h"

namespace eamos::deploy {

/// Version of the mission file format; a DEX refuses files of another major version.
constexpr int kMissionFormatVersion = 1;

/// SHA-256 (hex) over the whole compiled mission: the MEG with every node's content and
/// every drone's settings and type. Two drones holding files with the same hash run the
/// same mission.
std::string mission_hash(const graph::Compilation& c);

/// The mission file of one drone: its settings and capabilities, the fleet's drone
/// names, and its MDG with every internal node and the external nodes it links to.
/// As a document, for tests and tools; files are written by write_drone_mission.
nlohmann::json drone_mission(const graph::Compilation& c, int drone, const std::string& hash);

/// Writes drone_mission()'s content as JSON to `out`, node by node, without building the
/// document in memory. Returns false when the stream failed.
bool write_drone_mission(std::ostream& out, const graph::Compilation& c, int drone,
                         const std::string& hash);

/// The deployment manifest: hash, source and one entry per drone folder.
nlohmann::json manifest(const graph::Compilation& c, const std::string& hash);

/// Writes DIR/manifest.json and DIR/<drone>/mission.json for every drone. Returns false
/// and reports to `diags` when a file cannot be written.
bool write_deployment(const graph::Compilation& c, const std::string& dir, Diagnostics& diags);

}  // namespace eamos::deploy
