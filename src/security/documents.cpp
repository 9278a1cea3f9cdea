// The governance and permissions documents (OMG DDS Security 1.1, 9.4.1.2-3).
#include <string>

#include "security/mission_keys.h"
#include "transport/partitions.h"

namespace eamos::security {

namespace {

// Every domain id eamos accepts (--domain 0-230): the mission may run on any of them.
const char* kDomains = "<domains><id_range><min>0</min><max>230</max></id_range></domains>";

std::string topics(std::initializer_list<const char*> names) {
  std::string out = "<topics>";
  for (const char* n : names) out += std::string("<topic>") + n + "</topic>";
  return out + "</topics>";
}

}  // namespace

std::string governance_xml() {
  // ENCRYPT is AES-GCM: encrypted and authenticated ("signed") at once. Discovery,
  // liveliness and whole RTPS messages, each with its sender participant's key, so every
  // submessage and payload is inside one. Protecting submessages and payloads once more
  // (metadata/data protection) would add no secret, yet costs every matched pair of
  // endpoints its own key exchange: 16 more DDS Security messages per pair of drones, which
  // slowed the start of a fleet on one host (docs/performance.md).
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      )" + std::string(kDomains) + R"(
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>ENCRYPT</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>NONE</metadata_protection_kind>
          <data_protection_kind>NONE</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
)";
}

std::string permissions_xml(const std::string& subject, const std::string& mission_hash, int who,
                            const std::string& not_before, const std::string& not_after) {
  const bool ground = who == transport::kGroundParticipant;
  // A drone writes its triggers, telemetry, status, trace and lifecycle (READY, its ABORT,
  // the lead's FINISHED); the ground only lifecycle (START, ABORT). Each only in its own
  // partition, which is how a receiver knows who wrote a sample.
  std::string publish = ground ? topics({"eamos_lifecycle"})
                               : topics({"eamos_trigger", "eamos_telemetry", "eamos_lifecycle", "eamos_status",
                                         "eamos_trace"});
  std::string subscribe = ground ? topics({"eamos_trigger", "eamos_telemetry", "eamos_lifecycle", "eamos_status",
                                           "eamos_trace"})
                                 : topics({"eamos_trigger", "eamos_telemetry", "eamos_lifecycle", "eamos_status"});
  std::string own = transport::partition_of(mission_hash, who);
  std::string all = transport::partition_prefix(mission_hash) + "*";
  std::string name = ground ? "ground" : "drone" + std::to_string(who);
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name=")" + name + R"(">
      <subject_name>)" + subject + R"(</subject_name>
      <validity><not_before>)" + not_before + "</not_before><not_after>" + not_after + R"(</not_after></validity>
      <allow_rule>
        )" + kDomains + R"(
        <publish>)" + publish + "<partitions><partition>" + own + R"(</partition></partitions></publish>
        <subscribe>)" + subscribe + "<partitions><partition>" + all + R"(</partition></partitions></subscribe>
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
)";
}

}  // namespace eamos::security
