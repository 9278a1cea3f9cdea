#pragma once
// A deployment's manifest (DIR/manifest.json, written by `eamos compile -o DIR`) read back, for
// the ground, the terminal's status lines and the monitor: nothing in it is trusted.
#include <cstdint>
#include <string>
#include <vector>

namespace eamos::deploy {

/// A deployment's manifest as read back: what a ground, a terminal view or a monitor needs.
struct DeployedDrone {
  std::string name;
  std::string folder;  ///< DIR/folder: one name inside the deployment, never a path out of it
};
struct DeploymentManifest {
  std::string mission_hash;
  std::string source;  ///< the mission's source file as the compile was given it ("" if unnamed)
  std::vector<DeployedDrone> drones;
};

/// The most a manifest may hold (about 150 bytes per drone are written).
constexpr std::uint64_t kMaxManifestBytes = std::uint64_t{64} << 20;

/// Reads DIR/manifest.json, trusting nothing in it: false with `error` (a sentence that says
/// what to do) when it cannot be read, is not a deployment manifest, lists no drones or names a
/// drone's folder that is not one name inside DIR.
bool read_manifest(const std::string& dir, DeploymentManifest& out, std::string& error);

}  // namespace eamos::deploy
