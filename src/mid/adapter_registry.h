#pragma once
// The Adapter Space (paper, section VI): adapters registered by name, the way a
// BehaviorTree.CPP factory registers node types. A drone type's (or drone's) `adapter:` in
// the fleet file names the entry; an unknown name is an error value listing the known ones,
// found when the mission is set up, never in flight. Registries are values, not globals:
// a program registers what it links (sim::register_adapter, mavlink_adapter::register_adapter).
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "fleet/catalog.h"
#include "fleet/fleet.h"
#include "mid/drone_api.h"
#include "mid/event_loop.h"

namespace eamos::mid {

enum class CreateStatus {
  success,
  unknown_adapter,  ///< no adapter of that name is registered
  adapter_failed,   ///< the adapter could not make the drone (bad settings, no connection)
};
const char* create_status_name(CreateStatus s);

struct CreateResult {
  CreateStatus status = CreateStatus::success;
  std::unique_ptr<Drone> drone;  ///< set exactly when status is success
  std::string message;           ///< what went wrong and how to fix it; "" on success
};

/// Makes the Drone for one mission drone: its settings (home, limits, sensors, timeouts,
/// connection), its type (capabilities, sensor count) and the loop it runs on.
using AdapterFactory = std::function<CreateResult(
    const fleet::DroneSettings& settings, const fleet::DroneType& type, EventLoop& loop)>;

class AdapterRegistry {
 public:
  /// Adds an adapter; a second registration under the same name replaces the first.
  void register_adapter(const std::string& name, AdapterFactory factory);
  bool has(const std::string& name) const { return factories_.count(name) != 0; }
  /// Registered names, sorted.
  std::vector<std::string> names() const;

  /// Creates a drone with the adapter called `name` (usually settings.adapter).
  CreateResult create(const std::string& name, const fleet::DroneSettings& settings,
                      const fleet::DroneType& type, EventLoop& loop) const;

 private:
  std::map<std::string, AdapterFactory> factories_;
};

}  // namespace eamos::mid
