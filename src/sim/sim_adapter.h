#pragma once
// Registers the built-in simulator in an Adapter Space registry under the name "sim", the
// fleet file's default adapter.
#include "mid/adapter_registry.h"
#include "sim/sim_drone.h"

namespace eamos::sim {

inline constexpr const char* kAdapterName = "sim";

/// Adds the "sim" adapter: every drone it creates is a SimDrone with `options`.
void register_adapter(mid::AdapterRegistry& registry, SimOptions options = {});

}  // namespace eamos::sim
