#pragma once
// Where trace events go: a JSON Lines file (one event per line), the live log a person
// reads while the mission runs, and a fan-out to both.
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dex/trace.h"

namespace eamos::dex {

/// One event as a line of the JSON Lines trace (docs/trace.md): what JsonlTrace writes and what
/// the Python module hands to a run's callback. `fleet` names the drones of message events'
/// from/to (an index past its end is written as the number).
nlohmann::ordered_json trace_event_json(const TraceEvent& e, const std::vector<std::string>& fleet);

/// {"t":1.25,"drone":"Drone1","event":"start","name":"Takeoff","line":51,...} per line, in
/// the schema of docs/trace.md. `fleet` names the drones of message events' from/to.
/// Each line goes out as it is written, so a write that fails (a full disk) is known at
/// once: `on_write_error` hears it then, with the system's reason, and nothing more is
/// written (a trace with a hole would read as whole).
class JsonlTrace : public TraceSink {
 public:
  explicit JsonlTrace(std::ostream& out, std::vector<std::string> fleet = {}) : out_(out), fleet_(std::move(fleet)) {}
  void record(const TraceEvent& e) override;
  /// The trace's first line (deploy::trace_header makes it).
  void write_header(const nlohmann::ordered_json& header);
  void on_write_error(std::function<void(const std::string& why)> fn) { on_error_ = std::move(fn); }
  /// Why a line could not be written ("No space left on device"); "" while none failed.
  const std::string& write_error() const { return error_; }

 private:
  void write(const nlohmann::ordered_json& j);
  std::ostream& out_;
  std::vector<std::string> fleet_;
  std::function<void(const std::string&)> on_error_;
  std::string error_;
};

/// "   12.40 s  Drone1  end    Drone1.Takeoff(3)  succeeded   line 51"; telemetry and
/// message events are not shown.
class LiveLog : public TraceSink {
 public:
  explicit LiveLog(std::ostream& out) : out_(out) {}
  void record(const TraceEvent& e) override;
  bool takes_messages() const override { return false; }  // a person reads actions, not triggers
  /// Whether each line goes out when it is logged (the default: a terminal, a pipe, a file
  /// someone follows while the drones fly in real time), or when the stream's buffer
  /// fills and at the end: a run on virtual time into a file, where a write per line was
  /// a tenth of a 1,000-drone run's CPU. Anything written to std::cerr, which is tied to
  /// std::cout, flushes it first, so the two stay in order in one file.
  void set_flush_each_line(bool on) { flush_each_line_ = on; }

 private:
  std::ostream& out_;
  bool flush_each_line_ = true;
  std::string line_;  ///< the line being put together, its room kept from line to line
};

class TeeTrace : public TraceSink {
 public:
  void add(TraceSink* sink) { sinks_.push_back(sink); }
  void record(const TraceEvent& e) override {
    for (TraceSink* s : sinks_) s->record(e);
  }
  bool takes_messages() const override {
    for (TraceSink* s : sinks_)
      if (s->takes_messages()) return true;
    return false;
  }

 private:
  std::vector<TraceSink*> sinks_;
};

/// Keeps every event in memory (tests, summaries, plots).
class MemoryTrace : public TraceSink {
 public:
  void record(const TraceEvent& e) override { events.push_back(e); }
  std::vector<TraceEvent> events;
};

}  // namespace eamos::dex
