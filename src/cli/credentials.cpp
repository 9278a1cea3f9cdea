// The DDS Security credentials made in this process: `eamos run --distributed`'s, and those of
// a compile eamos-fly runs itself. Apart from commands.cpp so that `eamos`, which leaves them
// to eamos-credentials, does not link OpenSSL (src/cli/CMakeLists.txt).
#include <iostream>

#include "cli/arguments.h"
#include "cli/commands.h"
#include "security/mission_keys.h"

namespace eamos::cli {

namespace {

bool make_credentials(const std::vector<std::string>& drones, const std::string& dir, const std::string& hash,
                      const SecurityOptions& security) {
  security::MissionKeysRequest r{dir, hash, drones, security.keys_dir, security.valid_days};
  std::vector<std::string> notes;
  std::string error;
  if (!security::write_mission_keys(r, notes, error)) {
    std::cerr << error_prefix() << "cannot make the mission's DDS Security credentials: " << error << "\n";
    return false;
  }
  for (const std::string& n : notes) std::cout << n << "\n";
  return true;
}

}  // namespace

int finish_in_process(const CompileEnding& end) {
  if (!make_credentials(end.drones, end.out_dir, end.hash, end.security)) return 1;
  std::cout << end.done;
  return 0;
}

bool write_security(const graph::Compilation& c, const std::string& dir, const std::string& hash,
                    const SecurityOptions& security) {
  if (!security.insecure) return make_credentials(drone_names(c), dir, hash, security);
  security::remove_mission_keys(dir, drone_names(c));
  return true;
}

}  // namespace eamos::cli
