#pragma once
// Mission synthesis and deployment (paper, sections IV.D–E). The paper generates Go
// source per drone and compiles it; eamos writes one self-contained, versioned data file
// per drone that a single generic DEX loads (docs/architecture.md says why).
#include <string>

#include <nlohmann/json.hpp>

#include "deploy/mission_file.h"
#include "diag/diagnostics.h"
#include "graph/pipeline.h"

namespace eamos::deploy {

/// The deployment manifest: hash, source and one entry per drone folder.
nlohmann::json manifest(const graph::Compilation& c, const std::string& hash);

/// Writes DIR/manifest.json and DIR/<drone>/mission.json for every drone. Returns false
/// and reports to `diags` when a file cannot be written.
bool write_deployment(const graph::Compilation& c, const std::string& dir, Diagnostics& diags);

}  // namespace eamos::deploy
