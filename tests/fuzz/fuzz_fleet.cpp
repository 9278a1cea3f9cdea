// libFuzzer target of the fleet-file reader: any bytes as YAML must give diagnostics,
// never a crash or an uncaught exception.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "fleet/fleet.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto source = std::make_shared<eamos::SourceFile>(
      "fuzz.yaml", std::string(reinterpret_cast<const char*>(data), size));
  eamos::Diagnostics diags;
  eamos::fleet::Fleet fleet;
  eamos::fleet::parse_fleet(source, fleet, diags);
  (void)diags.format();
  return 0;
}
