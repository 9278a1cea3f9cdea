#pragma once
// Who may write what is bound to DDS partitions: every participant of a mission writes in
// one partition of its own, "eamos.<mission hash>.<drone index>" or
// "eamos.<mission hash>.ground", and reads the partitions of the whole mission. With DDS
// Security on, a participant's signed permissions let it write only in its own partition
// (src/security writes them), so the partition a sample's writer is in names the identity
// that authenticated it; DdsNode drops a sample whose sender field names someone else.
#include <string>

namespace eamos::transport {

inline constexpr int kGroundParticipant = -1;  ///< the ground process (as samples.h's kGround)
inline constexpr int kUnknownSender = -2;      ///< a writer outside the mission's partitions

inline std::string partition_prefix(const std::string& mission_hash) { return "eamos." + mission_hash + "."; }

/// The partition participant `who` (a drone index or kGroundParticipant) writes in.
inline std::string partition_of(const std::string& mission_hash, int who) {
  return partition_prefix(mission_hash) + (who == kGroundParticipant ? std::string("ground") : std::to_string(who));
}

/// Whose partition `partition` is: a drone index below `drones`, kGroundParticipant, or
/// kUnknownSender.
inline int participant_of(const std::string& mission_hash, int drones, const std::string& partition) {
  std::string prefix = partition_prefix(mission_hash);
  if (partition.compare(0, prefix.size(), prefix) != 0) return kUnknownSender;
  std::string rest = partition.substr(prefix.size());
  if (rest == "ground") return kGroundParticipant;
  if (rest.empty() || rest.size() > 6 || rest.find_first_not_of("0123456789") != std::string::npos ||
      (rest.size() > 1 && rest[0] == '0'))
    return kUnknownSender;
  int d = std::stoi(rest);
  return d < drones ? d : kUnknownSender;
}

}  // namespace eamos::transport
