#include "sim/sim_adapter.h"

#include <memory>

namespace eamos::sim {

void register_adapter(mid::AdapterRegistry& registry, SimOptions options) {
  registry.register_adapter(
      kAdapterName,
      [options](const fleet::DroneSettings& settings, const fleet::DroneType& type,
                mid::EventLoop& loop) -> mid::CreateResult {
        if (!(options.step_hz > 0.0))
          return {mid::CreateStatus::adapter_failed, nullptr,
                  "drone '" + settings.name + "': the simulator's step rate must be positive"};
        return {mid::CreateStatus::success,
                std::make_unique<SimDrone>(settings, type, loop, options), ""};
      });
}

}  // namespace eamos::sim
