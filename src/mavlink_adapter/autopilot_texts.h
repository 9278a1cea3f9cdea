#pragma once
// The autopilot's own words: STATUSTEXT, assembled from its chunks, kept for a while so that
// a refusal can quote why (ArduPilot queues the text and sends it after the COMMAND_ACK).
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "mavlink/payloads.h"

namespace eamos::mavlink_adapter {

class AutopilotTexts {
 public:
  /// Folds a STATUSTEXT in, received at mission time `now`: the texts that are whole now, as
  /// the trace should show them ("ArduPilot warning: …"), oldest first; none while a text
  /// waits for its next chunk.
  std::vector<std::string> add(const mavlink::Statustext& t, double now, const char* autopilot);
  /// The text still waiting for a chunk, once it has waited kChunkWaitS: a text of exactly
  /// 50, 100, … characters has no short last chunk to end it (PX4 sends none).
  std::vector<std::string> flush(double now, const char* autopilot);
  /// "; ArduPilot says: …": its warnings and errors since `since` (mission s), or "".
  std::string says(double since, const char* autopilot) const;

 private:
  struct Text {
    double t;
    uint8_t severity;
    std::string text;
  };
  std::string finish(const char* autopilot);

  std::deque<Text> texts_;  ///< the autopilot's recent STATUSTEXTs, newest last
  /// The text being assembled: at most one, as a sender sends one text's chunks back to back.
  std::optional<Text> pending_;
  uint16_t pending_id_ = 0;
};

}  // namespace eamos::mavlink_adapter
