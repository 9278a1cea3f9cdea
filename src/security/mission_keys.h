#pragma once
// A mission's DDS Security credentials (docs/security.md): an identity CA and a
// permissions CA, one identity (certificate and private key) per drone and one for the
// ground, the signed governance (every topic and discovery signed and encrypted, no
// unauthenticated participant) and, per participant, signed permissions that let it
// write only in its own partition (transport/partitions.h) and only its own topics.
// Each drone's folder gets its own private key and nothing else secret.
#include <string>
#include <vector>

namespace eamos::security {

/// Where the ground's credentials go: not a drone name (identifiers have no '-').
inline constexpr const char* kGroundFolder = "ground-station";
/// Under each participant's folder: the files DdsOptions::security_folder names.
inline constexpr const char* kSecuritySubfolder = "security";

struct MissionKeysRequest {
  std::string deploy_dir;             ///< written by deploy::write_deployment
  std::string mission_hash;
  std::vector<std::string> drones;    ///< by index, as in the mission
  /// Holds the two CAs (certificate and key); made there when it has none. "": fresh CAs
  /// whose keys are never written, so no one can make credentials for this mission later.
  std::string keys_dir;
  int valid_days = 30;                ///< of every certificate and permission made
};

/// Writes every participant's security folder; false with `error` (what, and how to fix).
/// `notes` says what was made or used, for the user.
bool write_mission_keys(const MissionKeysRequest& r, std::vector<std::string>& notes, std::string& error);

/// Removes the security folders of DIR (a deployment compiled with --insecure must not
/// keep another compilation's credentials).
void remove_mission_keys(const std::string& deploy_dir, const std::vector<std::string>& drones);

/// The documents, unsigned (for tests and docs).
std::string governance_xml();
/// `who`: a drone index or transport::kGroundParticipant.
std::string permissions_xml(const std::string& subject, const std::string& mission_hash, int who,
                            const std::string& not_before, const std::string& not_after);

}  // namespace eamos::security
