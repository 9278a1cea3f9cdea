// libFuzzer target of the mission reader: any bytes as a mission file must give defects
// ("FILE: error: ..."), never a crash, a hang or an uncaught exception. Each input is read
// twice: as it is, and with its file hash recomputed (when it has one), so that mutations
// get past the hash check and reach every member the reader checks.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "deploy/mission_file.h"
#include "support/mission_edit.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  eamos::dex::Mission mission;
  std::vector<std::string> errors;
  eamos::deploy::read_mission(text, "fuzz.json", mission, errors);
  std::string sealed;
  try {
    sealed = eamos_test::reseal(text);
  } catch (const std::runtime_error&) {
    return 0;  // no file hash member to recompute
  }
  errors.clear();
  if (eamos::deploy::read_mission(sealed, "fuzz.json", mission, errors)) {
    // An accepted mission is one the engine may index without checks: prove it here.
    for (const auto& a : mission.arcs)
      if (a.from < 0 || a.to < 0 || a.from >= static_cast<int>(mission.nodes.size()) ||
          a.to >= static_cast<int>(mission.nodes.size()))
        __builtin_trap();
    for (const auto& n : mission.nodes) {
      if (n.drone < 0 || n.drone >= static_cast<int>(mission.fleet.size())) __builtin_trap();
      for (int c : n.cancels)
        if (c < 0 || c >= static_cast<int>(mission.nodes.size())) __builtin_trap();
    }
    if (mission.self < 0 || mission.self >= static_cast<int>(mission.fleet.size())) __builtin_trap();
  }
  return 0;
}
