#pragma once
// Where trace events go: a JSON Lines file (one event per line), the live log a person
// reads while the mission runs, and a fan-out to both.
#include <ostream>
#include <vector>

#include "dex/trace.h"

namespace eamos::dex {

/// {"t":1.25,"drone":"Drone1","event":"start","name":"Takeoff","line":51,...} per line.
class JsonlTrace : public TraceSink {
 public:
  explicit JsonlTrace(std::ostream& out) : out_(out) {}
  void record(const TraceEvent& e) override;

 private:
  std::ostream& out_;
};

/// "   12.40 s  Drone1  end    Drone1.Takeoff(3)  succeeded   line 51"
class LiveLog : public TraceSink {
 public:
  explicit LiveLog(std::ostream& out) : out_(out) {}
  void record(const TraceEvent& e) override;

 private:
  std::ostream& out_;
};

class TeeTrace : public TraceSink {
 public:
  void add(TraceSink* sink) { sinks_.push_back(sink); }
  void record(const TraceEvent& e) override {
    for (TraceSink* s : sinks_) s->record(e);
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
