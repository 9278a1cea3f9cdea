#pragma once
// Registers the MAVLink adapter in an Adapter Space registry under the name "mavlink". A
// drone's `connection:` (a URL, fleet/link_url.h) and `sysid:` come from the fleet file.
#include "mavlink_adapter/mavlink_drone.h"
#include "mid/adapter_registry.h"

namespace eamos::mavlink_adapter {

inline constexpr const char* kAdapterName = "mavlink";

/// Adds the "mavlink" adapter. Creating a drone opens its link and waits for the vehicle's
/// first HEARTBEAT (up to options.connect_timeout_s); it fails unless options.real_time.
void register_adapter(mid::AdapterRegistry& registry, MavlinkOptions options = {});

}  // namespace eamos::mavlink_adapter
