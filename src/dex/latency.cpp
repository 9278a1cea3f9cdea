#include "dex/latency.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace eamos::dex {

bool is_drone_message(const TraceEvent& e) {
  return e.event == "message" && (e.kind == "trigger" || e.kind == "cancel") && e.from >= 0 && e.to >= 0;
}

std::string drone_name_of(const std::vector<std::string>& fleet, int index) {
  return index >= 0 && index < static_cast<int>(fleet.size()) ? fleet[index] : "?";
}

LateMessage late_message(const TraceEvent& e, const std::vector<std::string>& fleet) {
  return {e.kind, drone_name_of(fleet, e.from), drone_name_of(fleet, e.to), e.node, e.sent, latency_of(e)};
}

MessageLatency message_latency(const std::vector<TraceEvent>& events, const std::vector<std::string>& fleet,
                               double warn_s) {
  MessageLatency m;
  m.warn_s = warn_s;
  std::vector<double> all;
  for (const TraceEvent& e : events) {
    if (!is_drone_message(e)) continue;
    double latency = latency_of(e);
    all.push_back(latency);
    if (latency > warn_s) m.late.push_back(late_message(e, fleet));
  }
  m.count = all.size();
  if (all.empty()) return m;
  std::sort(all.begin(), all.end());
  m.max_s = all.back();
  // Nearest rank: the smallest latency at least 99 % of the messages do not exceed.
  auto rank = static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(all.size())));
  m.p99_s = all[std::max<std::size_t>(rank, 1) - 1];
  return m;
}

std::string describe_late(const LateMessage& m) {
  char text[96];
  std::snprintf(text, sizeof text, " was received %.3f mission s after it was sent at %.3f s", m.latency, m.sent);
  return m.kind + " from " + m.from + " to " + m.to + " (node " + std::to_string(m.node) + ")" + text;
}

}  // namespace eamos::dex
