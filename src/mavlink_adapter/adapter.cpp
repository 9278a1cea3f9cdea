#include "mavlink_adapter/adapter.h"

#include <algorithm>
#include <memory>

#include "diag/printable.h"
#include "fleet/link_url.h"

namespace eamos::mavlink_adapter {

void register_adapter(mid::AdapterRegistry& registry, MavlinkOptions options) {
  registry.register_adapter(
      kAdapterName,
      [options](const fleet::DroneSettings& settings, const fleet::DroneType& type,
                mid::EventLoop& loop) -> mid::CreateResult {
        auto failed = [&](const std::string& why) {
          return mid::CreateResult{mid::CreateStatus::adapter_failed, nullptr,
                                   "drone '" + settings.name + "': " + why};
        };
        if (!options.real_time)
          return failed("the mavlink adapter flies real vehicles, which cannot follow virtual "
                        "time: run with --realtime (or --speed 1)");
        if (settings.connection.empty())
          return failed("no `connection:` in the fleet file, e.g. connection: udp://:14540");
        fleet::EndpointResult url = fleet::parse_link_url(settings.connection);
        if (!url.endpoint) return failed("connection '" + diag::printable(settings.connection, 120) + "': " + url.error);
        MavlinkOptions scaled = options;  // wall-clock budgets into mission seconds
        scaled.link_timeout_s = std::max(options.link_timeout_s, options.link_timeout_min_wall_s * options.speed);
        scaled.commands.ack_timeout_s *= options.speed;
        scaled.commands.in_progress_s *= options.speed;
        scaled.mode_confirm_s *= options.speed;
        scaled.statustext_wait_s *= options.speed;
        scaled.picture_confirm_s *= options.speed;
        scaled.fence_reply_s *= options.speed;
        auto drone = std::make_unique<MavlinkDrone>(settings, type, loop, scaled);
        if (std::string error = drone->connect(*url.endpoint); !error.empty()) return failed(error);
        return {mid::CreateStatus::success, std::move(drone), ""};
      });
}

}  // namespace eamos::mavlink_adapter
