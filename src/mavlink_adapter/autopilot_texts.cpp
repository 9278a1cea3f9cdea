#include "mavlink_adapter/autopilot_texts.h"

namespace eamos::mavlink_adapter {

namespace {

constexpr std::size_t kTextsKept = 32;
constexpr std::size_t kMaxTextLength = 50 * 8;  ///< longest text assembled from chunks
constexpr std::size_t kMaxChunkedTexts = 4;     ///< texts being assembled at once
constexpr uint8_t kSeverityWarning = 4;  ///< MAV_SEVERITY_WARNING: refusals explain at or above it

const char* severity_name(uint8_t s) {
  static const char* names[] = {"emergency", "alert", "critical", "error", "warning", "notice", "info", "debug"};
  return s < 8 ? names[s] : "unknown";
}

}  // namespace

std::optional<std::string> AutopilotTexts::add(const mavlink::Statustext& t, double now, const char* autopilot) {
  std::string text = t.text;
  if (t.id != 0) {
    // A text longer than 50 characters comes in chunks of one id; a chunk shorter than 50
    // is the last. Bounded: a sender that never ends a text cannot grow this without limit.
    std::string& pending = chunks_[t.id];
    pending += t.text;
    if (t.text.size() >= 50 && pending.size() < kMaxTextLength && chunks_.size() <= kMaxChunkedTexts)
      return std::nullopt;
    text = pending;
    chunks_.erase(t.id);
  }
  texts_.push_back({now, t.severity, text});
  if (texts_.size() > kTextsKept) texts_.pop_front();
  return std::string(autopilot) + " " + severity_name(t.severity) + ": " + text;
}

std::string AutopilotTexts::says(double since, const char* autopilot) const {
  std::string said;
  for (const Text& t : texts_) {
    if (t.t < since || t.severity > kSeverityWarning) continue;
    if (said.find(t.text) != std::string::npos) continue;  // the same text repeated
    said += (said.empty() ? "" : "; ") + t.text;
  }
  return said.empty() ? "" : std::string("; ") + autopilot + " says: " + said;
}

}  // namespace eamos::mavlink_adapter
