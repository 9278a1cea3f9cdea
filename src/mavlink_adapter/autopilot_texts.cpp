#include "mavlink_adapter/autopilot_texts.h"

namespace eamos::mavlink_adapter {

namespace {

constexpr std::size_t kTextsKept = 32;
constexpr std::size_t kMaxTextLength = 50 * 8;  ///< longest text assembled from chunks
constexpr double kChunkWaitS = 1.0;             ///< mission s a text waits for its next chunk
constexpr uint8_t kSeverityWarning = 4;  ///< MAV_SEVERITY_WARNING: refusals explain at or above it

const char* severity_name(uint8_t s) {
  static const char* names[] = {"emergency", "alert", "critical", "error", "warning", "notice", "info", "debug"};
  return s < 8 ? names[s] : "unknown";
}

}  // namespace

// A text longer than 50 characters comes in chunks of one id, each filling its field but the
// last. The id is not trusted to say more: PX4 numbers every text from 0, which MAVLink
// reserves for a text of one chunk, so a full chunk waits for the next whatever its id. A
// text of another id, or a chunk 0 again, ends the one before.
std::vector<std::string> AutopilotTexts::add(const mavlink::Statustext& t, double now, const char* autopilot) {
  std::vector<std::string> whole;
  if (pending_ && (t.id != pending_id_ || t.chunk_seq == 0)) whole.push_back(finish(autopilot));
  if (!pending_) {
    pending_ = Text{now, t.severity, ""};
    pending_id_ = t.id;
  }
  pending_->text += t.text;
  if (!t.full || pending_->text.size() >= kMaxTextLength) whole.push_back(finish(autopilot));
  return whole;
}

std::vector<std::string> AutopilotTexts::flush(double now, const char* autopilot) {
  if (!pending_ || now - pending_->t < kChunkWaitS) return {};
  return {finish(autopilot)};
}

std::string AutopilotTexts::finish(const char* autopilot) {
  Text t = std::move(*pending_);
  pending_.reset();
  while (!t.text.empty() && t.text.back() == ' ') t.text.pop_back();
  std::string line = std::string(autopilot) + " " + severity_name(t.severity) + ": " + t.text;
  texts_.push_back(std::move(t));
  if (texts_.size() > kTextsKept) texts_.pop_front();
  return line;
}

std::string AutopilotTexts::says(double since, const char* autopilot) const {
  std::string said;
  auto quote = [&](const Text& t) {
    if (t.t < since || t.severity > kSeverityWarning) return;
    if (said.find(t.text) != std::string::npos) return;  // the same text repeated
    said += (said.empty() ? "" : "; ") + t.text;
  };
  for (const Text& t : texts_) quote(t);
  if (pending_) quote(*pending_);  // its last chunk may still come: what came so far
  return said.empty() ? "" : std::string("; ") + autopilot + " says: " + said;
}

}  // namespace eamos::mavlink_adapter
