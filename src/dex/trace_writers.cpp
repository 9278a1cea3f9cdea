#include "dex/trace_writers.h"

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

namespace eamos::dex {

namespace {
// Times are rounded to the microsecond so that traces compare byte for byte.
double rounded(double t) { return std::round(t * 1e6) / 1e6; }
}  // namespace

void JsonlTrace::record(const TraceEvent& e) {
  nlohmann::ordered_json j;
  j["t"] = rounded(e.t);
  j["drone"] = e.drone;
  j["event"] = e.event;
  j["name"] = e.name;
  j["line"] = e.line;
  if (!e.text.empty()) j["text"] = e.text;
  if (!e.outcome.empty()) j["outcome"] = e.outcome;
  if (e.value) j["value"] = *e.value;
  if (e.reading) j["value"] = *e.reading;
  if (!e.reason.empty()) j["reason"] = e.reason;
  if (!e.failure.empty()) j["failure"] = e.failure;
  if (!e.detail.empty()) j["detail"] = e.detail;
  // Reasons come from outside (an autopilot's text, another process's ABORT): a byte that
  // is not UTF-8 becomes U+FFFD instead of an exception that loses the rest of the trace.
  out_ << j.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << '\n';
}

void LiveLog::record(const TraceEvent& e) {
  char head[64];
  std::snprintf(head, sizeof head, "%9.2f s  %-8s %-9s ", e.t, e.drone.c_str(), e.event.c_str());
  out_ << head << (e.text.empty() ? e.name : e.text);
  if (!e.outcome.empty()) out_ << "  " << e.outcome;
  if (!e.failure.empty()) out_ << " [" << e.failure << "]";
  if (e.value) out_ << "  → " << (*e.value ? "true" : "false");
  if (e.reading) out_ << "  = " << *e.reading;
  if (!e.reason.empty()) out_ << "  (" << e.reason << ")";
  if (e.line > 0) out_ << "   line " << e.line;
  // Live: a line is out when it happened, also through a pipe (`eamos run | tee`, a test
  // that acts on a line), not when a buffer fills.
  out_ << '\n' << std::flush;
}

}  // namespace eamos::dex
