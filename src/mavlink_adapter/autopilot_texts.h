#pragma once
// The autopilot's own words: STATUSTEXT, assembled from its chunks, kept for a while so that
// a refusal can quote why (ArduPilot queues the text and sends it after the COMMAND_ACK).
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>

#include "mavlink/payloads.h"

namespace eamos::mavlink_adapter {

class AutopilotTexts {
 public:
  /// Folds a STATUSTEXT in, received at mission time `now`; the whole text once its last
  /// chunk came, as the trace should show it ("ArduPilot warning: …"), else nullopt.
  std::optional<std::string> add(const mavlink::Statustext& t, double now, const char* autopilot);
  /// "; ArduPilot says: …": its warnings and errors since `since` (mission s), or "".
  std::string says(double since, const char* autopilot) const;

 private:
  struct Text {
    double t;
    uint8_t severity;
    std::string text;
  };
  std::deque<Text> texts_;  ///< the autopilot's recent STATUSTEXTs, newest last
  std::map<uint16_t, std::string> chunks_;  ///< STATUSTEXT id -> the chunks so far
};

}  // namespace eamos::mavlink_adapter
