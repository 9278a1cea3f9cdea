#pragma once
// What `eamos compile --package` adds to a deployment so that each drone's companion
// computer can run its DEX as a systemd service (docs/deploy.md). Beside mission.json and
// security/ (written by write_deployment and the security component), every drone's
// folder gets: cyclonedds.xml (DDS over a real network, config/cyclonedds-network.xml),
// dex.env (the interface and options of its service), eamos-dex@.service (the unit,
// config/eamos-dex@.service) and DEPLOY.txt (what to copy where, for that drone). The
// ground's folder gets cyclonedds.xml too, for `eamos launch --remote-only`.
#include <string>

#include "diag/diagnostics.h"
#include "graph/pipeline.h"

namespace eamos::deploy {

struct PackageOptions {
  /// The network interface every DEX's DDS binds (EAMOS_DDS_INTERFACE in dex.env);
  /// "": left for the user to set in each dex.env (the DEX refuses to start until then).
  std::string interface;
  int domain = 0;         ///< DDS domain id every DEX joins (0-230); the ground's must match
  bool insecure = false;  ///< compiled without credentials: the DEXes run with --insecure
  /// The ground's folder under the deployment (security::kGroundFolder); "" = none.
  std::string ground_folder;
};

/// The unit file's text, the one `cmake --install` installs as eamos-dex@.service.
const char* dex_service_unit();
/// The Cyclone DDS configuration for a real network (interface from EAMOS_DDS_INTERFACE).
const char* network_dds_config();
/// A drone's dex.env.
std::string dex_env(const std::string& drone, const PackageOptions& o);

/// True when `name` can be a Linux network interface name and is safe in dex.env: 1 to 15
/// letters, digits, '.', '_' or '-'.
bool valid_interface_name(const std::string& name);
/// "" when the options can be packaged, else what is wrong and how to fix it.
std::string package_options_error(const PackageOptions& o);

/// Writes every drone's package files into DIR/<drone>/ (and the ground's configuration)
/// for a deployment write_deployment wrote to `dir`. False with the reason in `diags` when
/// an option is invalid or a file cannot be written.
bool write_packages(const graph::Compilation& c, const std::string& dir, const PackageOptions& o,
                    Diagnostics& diags);

}  // namespace eamos::deploy
