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

/// The version of the trace schema (docs/trace.md) this build writes.
constexpr int kTraceSchemaVersion = 1;

/// A trace's first line (docs/trace.md, "header"): the mission and fleet text embedded, so
/// a trace replays without its files; every drone with its index, type, home and the drones
/// whose telemetry it reads.
nlohmann::ordered_json trace_header(const graph::Compilation& c, const std::string& hash, double telemetry_hz);

/// Writes DIR/manifest.json, DIR/trace-header.json (the header `eamos launch` starts its
/// trace with) and DIR/<drone>/mission.json for every drone. Returns false
/// and reports to `diags` when a file cannot be written.
bool write_deployment(const graph::Compilation& c, const std::string& dir, Diagnostics& diags);
/// The same with the mission hash already taken (mission_hash(c)): a caller that needs it
/// again, for the credentials, takes it once, since at 500,000 statements it is a tenth of
/// the compile.
bool write_deployment(const graph::Compilation& c, const std::string& dir, const std::string& hash,
                      Diagnostics& diags);

}  // namespace eamos::deploy
