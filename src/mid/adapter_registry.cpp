#include "mid/adapter_registry.h"

namespace eamos::mid {

const char* create_status_name(CreateStatus s) {
  switch (s) {
    case CreateStatus::success: return "success";
    case CreateStatus::unknown_adapter: return "unknown_adapter";
    case CreateStatus::adapter_failed: return "adapter_failed";
  }
  return "adapter_failed";
}

void AdapterRegistry::register_adapter(const std::string& name, AdapterFactory factory) {
  factories_[name] = std::move(factory);
}

std::vector<std::string> AdapterRegistry::names() const {
  std::vector<std::string> out;
  for (const auto& [name, factory] : factories_) out.push_back(name);
  return out;
}

CreateResult AdapterRegistry::create(const std::string& name,
                                     const fleet::DroneSettings& settings,
                                     const fleet::DroneType& type, EventLoop& loop) const {
  auto it = factories_.find(name);
  if (it == factories_.end()) {
    std::string known;
    for (const auto& n : names()) known += (known.empty() ? "" : ", ") + n;
    if (known.empty()) known = "none";
    return {CreateStatus::unknown_adapter, nullptr,
            "drone '" + settings.name + "': no adapter named '" + name +
                "' in this program (known: " + known + ")"};
  }
  CreateResult result = it->second(settings, type, loop);
  // An adapter that claims success must deliver a drone; one that does not has failed.
  if (result.status == CreateStatus::success && !result.drone)
    return {CreateStatus::adapter_failed, nullptr,
            "drone '" + settings.name + "': adapter '" + name + "' made no drone"};
  return result;
}

}  // namespace eamos::mid
