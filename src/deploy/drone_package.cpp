#include "deploy/drone_package.h"

#include <cctype>
#include <filesystem>
#include <fstream>

#include "deploy/mission_file.h"
#include "package_files.h"

namespace eamos::deploy {

namespace fs = std::filesystem;

const char* dex_service_unit() { return kDexServiceUnit; }
const char* network_dds_config() { return kNetworkDdsConfig; }

bool valid_interface_name(const std::string& name) {
  // IFNAMSIZ is 16 with the terminating NUL. The value also lands in an XML attribute (by
  // Cyclone's expansion) and an environment file, so nothing that could break either.
  if (name.empty() || name.size() > 15) return false;
  for (char ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '.' && ch != '_' && ch != '-') return false;
  return true;
}

std::string package_options_error(const PackageOptions& o) {
  if (!o.interface.empty() && !valid_interface_name(o.interface))
    return "--interface '" + o.interface + "' is not a network interface name; give 1 to 15 letters, digits, "
           "'.', '_' or '-' as `ip -br link` lists them (e.g. wlan0)";
  if (o.domain < 0 || o.domain > 230)
    return "DDS domain " + std::to_string(o.domain) + " is out of range; use 0 to 230";
  return "";
}

std::string dex_env(const std::string& drone, const PackageOptions& o) {
  std::string text = "# " + drone + "'s DEX service (eamos-dex@" + drone +
                     ".service reads this file; docs/deploy.md).\n"
                     "# The network interface DDS uses to reach the other drones and the ground; `ip -br link`\n"
                     "# lists this computer's. Without it the DEX does not start and says why in the journal.\n";
  text += o.interface.empty() ? "#EAMOS_DDS_INTERFACE=wlan0\n" : "EAMOS_DDS_INTERFACE=" + o.interface + "\n";
  text += "# More options of `eamos dex` (eamos dex --help); the domain must be the ground's. Quoted, so\n"
          "# that a shell can read this file too: set -a; . ./dex.env; set +a\n";
  text += "EAMOS_DEX_ARGS=\"--domain " + std::to_string(o.domain) + (o.insecure ? " --insecure" : "") + "\"\n";
  return text;
}

namespace {

std::string deploy_notes(const graph::Compilation& c, int d, const std::string& hash, const PackageOptions& o) {
  const std::string& n = c.drone_name(d);
  const fleet::DroneSettings& s = c.settings[d];
  std::string adapter = s.adapter + (s.connection.empty() ? "" : ", connection " + s.connection);
  std::string text =
      n + "'s DEX: its part of " + fs::path(c.source->path).filename().string() + " (mission " + hash.substr(0, 12) +
      "), to run on " + n + "'s companion computer.\n\n"
      "  mission.json        its mission file, with its settings (adapter " + adapter + ")\n" +
      (o.insecure ? "" : "  security/           its DDS Security credentials; identity_key.pem is its secret key\n") +
      "  cyclonedds.xml      DDS on the network interface dex.env names, discovery by multicast\n"
      "  dex.env             the service's interface and `eamos dex` options\n"
      "  eamos-dex@.service  the systemd unit (the eamos .deb installs the same one)\n\n"
      "On the companion computer, with eamos installed, this folder copied to ~/" + n + ":\n"
      "  sudo useradd --system --user-group --home-dir /var/lib/eamos --shell /usr/sbin/nologin eamos"
      "   # only without the .deb, which made it\n"
      "  sudo rm -rf /var/lib/eamos/" + n + " && sudo mkdir -p /var/lib/eamos && sudo cp -r ~/" + n +
      " /var/lib/eamos/\n"
      "  sudo chown -R eamos:eamos /var/lib/eamos/" + n + "\n"
      "  sudo cp /var/lib/eamos/" + n + "/eamos-dex@.service /etc/systemd/system/   # only without the .deb\n"
      "  sudo systemctl daemon-reload && sudo systemctl enable --now eamos-dex@" + n + "\n"
      "  journalctl -u eamos-dex@" + n + " -f\n\n"
      "Then, on the ground station: EAMOS_DDS_INTERFACE=IFACE eamos launch DIR --remote-only --domain " +
      std::to_string(o.domain) + " --dds-config DIR/" + (o.ground_folder.empty() ? "ground-station" : o.ground_folder) +
      "/cyclonedds.xml\n";
  return text;
}

bool write_file(const fs::path& path, const std::string& text, Diagnostics& diags) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (out) return true;
  diags.error(nullptr, {}, "cannot write '" + path.string() + "'; check the output folder's permissions");
  return false;
}

}  // namespace

bool write_packages(const graph::Compilation& c, const std::string& dir, const PackageOptions& o,
                    Diagnostics& diags) {
  if (std::string error = package_options_error(o); !error.empty()) {
    diags.error(nullptr, {}, error);
    return false;
  }
  std::string hash = mission_hash(c);
  for (int d = 0; d < c.drone_count(); ++d) {
    fs::path folder = fs::path(dir) / c.drone_name(d);
    if (!write_file(folder / "cyclonedds.xml", network_dds_config(), diags) ||
        !write_file(folder / "dex.env", dex_env(c.drone_name(d), o), diags) ||
        !write_file(folder / "eamos-dex@.service", dex_service_unit(), diags) ||
        !write_file(folder / "DEPLOY.txt", deploy_notes(c, d, hash, o), diags))
      return false;
  }
  if (o.ground_folder.empty()) return true;
  fs::path ground = fs::path(dir) / o.ground_folder;
  std::error_code ec;
  fs::create_directories(ground, ec);
  if (ec) {
    diags.error(nullptr, {}, "cannot create '" + ground.string() + "': " + ec.message());
    return false;
  }
  return write_file(ground / "cyclonedds.xml", network_dds_config(), diags);
}

}  // namespace eamos::deploy
