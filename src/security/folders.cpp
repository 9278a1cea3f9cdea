// Apart from mission_keys.cpp, which needs OpenSSL: `eamos compile --insecure` removes old
// credentials without linking libcrypto (src/cli/CMakeLists.txt).
#include <filesystem>

#include "security/mission_keys.h"

namespace eamos::security {

void remove_mission_keys(const std::string& deploy_dir, const std::vector<std::string>& drones) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path dir(deploy_dir);
  for (const std::string& d : drones) fs::remove_all(dir / d / kSecuritySubfolder, ec);
  fs::remove_all(dir / kGroundFolder, ec);
}

}  // namespace eamos::security
