#include "dex/trace_writers.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <nlohmann/json.hpp>

namespace eamos::dex {

namespace {
// Times are rounded to the microsecond so that traces compare byte for byte.
double rounded(double t) { return std::round(t * 1e6) / 1e6; }
}  // namespace

namespace {
std::string fleet_name(const std::vector<std::string>& fleet, int index) {
  if (index < static_cast<int>(fleet.size())) return fleet[index];
  return std::to_string(index);
}

/// Telemetry is for people and pictures: millimetres, a tenth of a degree and a hundredth
/// of a percent are finer than any vehicle reports, and keep the trace small.
/// `v` to 1/`per_unit` (1000: millimetres); divided, not multiplied by the step, so that
/// the double printed is the short decimal ("4.35", not "4.3500000000000005").
double to_step(double v, double per_unit) { return std::round(v * per_unit) / per_unit; }

void put_telemetry(nlohmann::ordered_json& j, const mid::DroneState& s) {
  j["x"] = to_step(s.x, 1000);
  j["y"] = to_step(s.y, 1000);
  j["z"] = to_step(s.z, 1000);
  if (std::isfinite(s.heading)) j["heading"] = to_step(s.heading, 10);
  else j["heading"] = nullptr;
  j["armed"] = s.armed;
  j["landed"] = s.landed;
  j["battery"] = to_step(s.battery, 100);
  j["mode"] = s.mode;
}
}  // namespace

nlohmann::ordered_json trace_event_json(const TraceEvent& e, const std::vector<std::string>& fleet) {
  auto drone_name = [&fleet](int index) { return fleet_name(fleet, index); };
  nlohmann::ordered_json j;
  j["t"] = rounded(e.t);
  if (e.event == "telemetry" && e.state) {
    j["event"] = e.event;
    j["drone"] = e.drone;
    put_telemetry(j, *e.state);
  } else if (e.event == "message") {
    j["event"] = e.event;
    // "drone" is the receiver: per-drone readers see what reached each drone. A lifecycle
    // message comes from the ground (-1) or goes to every drone (-1, "*").
    j["drone"] = e.to < 0 ? "*" : drone_name(e.to);
    j["kind"] = e.kind;
    j["from"] = e.from < 0 ? "ground" : drone_name(e.from);
    j["to"] = e.to < 0 ? "*" : drone_name(e.to);
    if (e.node >= 0) j["node"] = e.node;
    if (e.instance >= 0) j["instance"] = e.instance;
    j["sent"] = rounded(e.sent);
    j["received"] = rounded(e.t);
    j["latency"] = rounded(e.t - e.sent);
    if (!e.reason.empty()) j["reason"] = e.reason;
  } else {
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
    if (!e.kind.empty()) j["kind"] = e.kind;
    if (!e.branch.empty()) j["branch"] = e.branch;
    if (e.node >= 0) j["node"] = e.node;
    if (e.instance >= 0) j["instance"] = e.instance;
    if (!e.other.empty()) j["other"] = e.other;
    else if (is_separation_event(e.event) && e.to >= 0) j["other"] = drone_name(e.to);
    if (e.distance) j["distance"] = *e.distance;
  }
  return j;
}

void JsonlTrace::record(const TraceEvent& e) { write(trace_event_json(e, fleet_)); }

void JsonlTrace::write_header(const nlohmann::ordered_json& header) { write(header); }

void JsonlTrace::write(const nlohmann::ordered_json& j) {
  if (!error_.empty()) return;
  // Reasons come from outside (an autopilot's text, another process's ABORT): a byte that
  // is not UTF-8 becomes U+FFFD instead of an exception that loses the rest of the trace.
  errno = 0;
  out_ << j.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << '\n' << std::flush;
  if (out_) return;
  error_ = errno != 0 ? std::strerror(errno) : "the write failed";
  if (on_error_) on_error_(error_);
}

void LiveLog::record(const TraceEvent& e) {
  // Samples, messages and the other nodes' ends are for the trace file and the monitor; the log a person reads
  // (and tests parse) stays what it always was.
  if (e.event == "telemetry" || e.event == "message" || e.event == "node") return;
  char head[64];
  std::snprintf(head, sizeof head, "%9.2f s  %-8s %-9s ", e.t, e.drone.c_str(), e.event.c_str());
  // The line is put together first and written once: into std::cout every << is a write
  // of its own into stdio, and a 1,000-drone run logs some 150,000 lines.
  std::string& line = line_;
  line.assign(head);
  line += e.text.empty() ? e.name : e.text;
  if (!e.outcome.empty()) line.append("  ").append(e.outcome);
  if (!e.failure.empty()) line.append(" [").append(e.failure).append("]");
  if (e.value) line.append("  → ").append(*e.value ? "true" : "false");
  if (e.reading) {
    line += "  = ";
    out_ << line << *e.reading;  // a reading as the stream writes numbers
    line.clear();
  }
  if (!e.other.empty()) line.append(" ").append(e.other);
  if (e.distance) {
    char d[32];
    std::snprintf(d, sizeof d, " %.1f m apart", *e.distance);
    line += d;
  }
  if (!e.reason.empty()) line.append("  (").append(e.reason).append(")");
  if (e.line > 0) line.append("   line ").append(std::to_string(e.line));
  // Live: a line is out when it happened, also through a pipe (`eamos run | tee`, a test
  // that acts on a line), not when a buffer fills.
  line += '\n';
  out_ << line;
  if (flush_each_line_) out_ << std::flush;
}

}  // namespace eamos::dex
