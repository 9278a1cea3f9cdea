#include "trace/trace_schema.h"

#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

namespace eamos::trace {

namespace {

using nlohmann::json;

/// Checks one line's fields, collecting what is wrong with it.
class LineCheck {
 public:
  LineCheck(const json& j, std::vector<std::string>& errors, int line) : j_(j), errors_(errors), line_(line) {}

  void fail(const std::string& what) { errors_.push_back("line " + std::to_string(line_) + ": " + what); }
  bool has(const char* f) const { return j_.contains(f); }
  bool string(const char* f) { return need(f, j_.contains(f) && j_[f].is_string(), "a string"); }
  bool boolean(const char* f) { return need(f, j_.contains(f) && j_[f].is_boolean(), "true or false"); }
  bool number(const char* f) {
    return need(f, j_.contains(f) && j_[f].is_number() && std::isfinite(j_[f].get<double>()), "a finite number");
  }
  bool integer(const char* f, long long lo) {
    bool ok = j_.contains(f) && j_[f].is_number_integer() && j_[f].get<long long>() >= lo;
    return need(f, ok, "an integer of at least " + std::to_string(lo));
  }
  void optional_integer(const char* f, long long lo) {
    if (has(f)) integer(f, lo);
  }
  void optional_string(const char* f) {
    if (has(f)) string(f);
  }
  void one_of(const char* f, const std::set<std::string>& values) {
    if (!string(f)) return;
    if (!values.count(j_[f].get<std::string>())) fail("\"" + std::string(f) + "\" is \"" + j_[f].get<std::string>() + "\", not one of the schema's values");
  }
  /// A drone of the header, or one of `extra` ("ground", "*").
  void drone(const char* f, const std::set<std::string>& fleet, const std::set<std::string>& extra = {}) {
    if (!string(f)) return;
    std::string name = j_[f].get<std::string>();
    if (!fleet.count(name) && !extra.count(name)) fail("\"" + std::string(f) + "\" names \"" + name + "\", which is not a drone of the header");
  }

 private:
  bool need(const char* f, bool ok, const std::string& what) {
    if (!ok) fail(std::string(j_.contains(f) ? "\"" : "missing \"") + f + "\"" + (j_.contains(f) ? " is not " : ", ") + what);
    return ok;
  }
  const json& j_;
  std::vector<std::string>& errors_;
  int line_;
};

/// `latency` (added field, optional for traces written before it): received - sent, each
/// rounded to the microsecond, so the difference may be off by one microsecond each way.
void check_latency(const json& j, LineCheck& c) {
  if (!c.has("latency") || !c.number("latency")) return;
  double latency = j["latency"].get<double>();
  double expected = j["received"].get<double>() - j["sent"].get<double>();
  if (latency < 0) c.fail("\"latency\" is negative");
  else if (std::abs(latency - expected) > 2.5e-6) c.fail("\"latency\" is not \"received\" - \"sent\"");
}

void check_header(const json& j, LineCheck& c, std::set<std::string>& fleet) {
  if (c.string("schema") && j["schema"] != "eamos-trace") c.fail("\"schema\" is not \"eamos-trace\"");
  if (c.integer("version", 1) && j["version"] != 1) c.fail("\"version\" " + j["version"].dump() + " is not 1, the version this eamos reads");
  c.string("mission");
  c.string("mission_hash");
  c.string("source");
  c.string("fleet");
  if (c.number("telemetry_hz") && j["telemetry_hz"].get<double>() < 0) c.fail("\"telemetry_hz\" is negative");
  if (!j.contains("drones") || !j["drones"].is_array() || j["drones"].empty()) {
    c.fail("\"drones\" is not a list of the mission's drones");
    return;
  }
  for (std::size_t i = 0; i < j["drones"].size(); ++i) {
    const json& d = j["drones"][i];
    std::string where = "drones[" + std::to_string(i) + "]";
    if (!d.is_object() || !d.contains("name") || !d["name"].is_string()) {
      c.fail(where + " has no \"name\"");
      continue;
    }
    if (!fleet.insert(d["name"].get<std::string>()).second) c.fail(where + " names a drone twice");
    if (!d.contains("index") || d["index"] != static_cast<int>(i)) c.fail(where + " \"index\" is not " + std::to_string(i));
    if (!d.contains("type") || !d["type"].is_string()) c.fail(where + " \"type\" is not a string");
    const json* home = d.contains("home") ? &d["home"] : nullptr;
    bool home_ok = home && home->is_array() && home->size() == 3;
    for (std::size_t k = 0; home_ok && k < 3; ++k) home_ok = (*home)[k].is_number();
    if (!home_ok) c.fail(where + " \"home\" is not [x, y, z]");
  }
}

/// `eamos verify --trace`: a rule the path broke, at the action responsible.
void check_violation(const json& j, LineCheck& c, const std::set<std::string>& fleet) {
  c.drone("drone", fleet);
  c.one_of("kind", {"separation", "geofence", "battery", "speed", "climb", "descent", "occupied_home",
                    "airborne_at_end", "armed_at_end", "never_ends", "action_failed"});
  c.integer("line", 0);
  c.optional_integer("col", 0);
  c.string("text");
  if (c.has("drones")) {
    bool ok = j["drones"].is_array();
    for (std::size_t i = 0; ok && i < j["drones"].size(); ++i)
      ok = j["drones"][i].is_string() && fleet.count(j["drones"][i].get<std::string>());
    if (!ok) c.fail("\"drones\" is not a list of drones of the header");
  }
  for (const char* f : {"x", "y", "z"})
    if (c.has(f)) c.number(f);
}

const std::set<std::string> kOutcomes = {"succeeded", "preempted", "cancelled", "failed"};

// long: the schema of docs/trace.md as a table, one branch per event, read side by side with the doc.
void check_event(const json& j, const std::string& event, LineCheck& c, const std::set<std::string>& fleet,
                 bool strict) {
  if (event == "start" || event == "end" || event == "condition" || event == "sensor") {
    c.drone("drone", fleet);
    c.string("name");
    c.integer("line", 0);
    c.integer("node", 0);
    c.optional_integer("instance", 0);
    c.optional_string("text");
    if (event == "end") {
      c.one_of("outcome", kOutcomes);
      c.optional_string("reason");
      if (j.contains("failure"))
        c.one_of("failure", {"refused", "timed_out", "link_lost", "vehicle_fault", "pilot_took_over"});
      c.optional_string("detail");
    }
    if (event == "condition") c.boolean("value");
    if (event == "sensor") c.number("value");
  } else if (event == "node") {
    c.drone("drone", fleet);
    c.one_of("kind", {"init", "fork", "terminal", "end", "pause", "condition"});
    c.string("name");
    c.integer("line", 0);
    c.integer("node", 0);
    c.optional_integer("instance", 0);
    c.one_of("outcome", {"started", "ended", "released"});
    c.optional_string("branch");
  } else if (event == "failsafe") {
    c.drone("drone", fleet);
    c.one_of("name", {"land", "return_home", "hover"});
    c.string("reason");
  } else if (event == "conflict" || event == "give_way" || event == "resume") {
    c.drone("drone", fleet);
    c.string("name");
    c.integer("line", 0);
    c.drone("other", fleet);
    if (c.number("distance") && j["distance"].get<double>() < 0) c.fail("\"distance\" is negative");
    c.string("reason");
  } else if (event == "vehicle") {
    c.drone("drone", fleet);
    c.string("text");
  } else if (event == "telemetry") {
    c.drone("drone", fleet);
    c.number("x");
    c.number("y");
    c.number("z");
    if (!c.has("heading")) c.fail("missing \"heading\", a number or null");
    else if (!j["heading"].is_null() && !(j["heading"].is_number() && j["heading"] >= 0 && j["heading"] <= 360))
      c.fail("\"heading\" is neither null nor degrees from 0 to 360");
    c.boolean("armed");
    c.boolean("landed");
    c.number("battery");
    c.string("mode");
  } else if (event == "message") {
    c.one_of("kind", {"trigger", "cancel", "finished", "abort", "status", "telemetry"});
    c.drone("from", fleet, {"ground"});
    c.drone("to", fleet, {"*"});
    std::string kind = j.value("kind", "");
    if (kind == "trigger" || kind == "cancel") c.integer("node", 0);
    c.optional_integer("instance", 0);
    if (c.number("sent") && c.number("received")) {
      if (j["received"] != j["t"]) c.fail("\"received\" is not the event's \"t\"");
      if (j["received"].get<double>() < j["sent"].get<double>()) c.fail("received before it was sent");
      check_latency(j, c);
    }
  } else if (event == "mission") {
    c.one_of("outcome", {"completed", "failed"});
    if (j.value("outcome", "") == "failed") c.string("reason");
  } else if (event == "violation") {
    check_violation(j, c, fleet);
  } else if (event == "error") {
    c.string("name");
  } else if (event == "header") {
    c.fail("a header after the first line");
  } else if (strict) {
    c.fail("event \"" + event + "\" is not defined by schema version 1");
  }
}

}  // namespace

std::vector<std::string> check_trace(std::istream& in, const TraceCheckOptions& options) {
  std::vector<std::string> errors;
  std::set<std::string> fleet;
  int number = 0;
  int mission_line = 0;
  double last_t = 0.0;
  for (std::string text; std::getline(in, text);) {
    ++number;
    json j = json::parse(text, nullptr, false);
    LineCheck c(j, errors, number);
    if (j.is_discarded() || !j.is_object()) {
      c.fail("not a JSON object");
      continue;
    }
    if (mission_line) c.fail("an event after the mission's end (line " + std::to_string(mission_line) + ")");
    if (!c.number("t") || !c.string("event")) continue;
    std::string event = j["event"].get<std::string>();
    double t = j["t"].get<double>();
    if (t < 0) c.fail("\"t\" is negative");
    if (number == 1) {
      if (event != "header") c.fail("the first line is not the header");
      else check_header(j, c, fleet);
      continue;
    }
    if (event == "mission") mission_line = number;
    // Events come in time order; the mission's end carries the instant the mission ended,
    // which the failsafe's landing (still traced) may outlast.
    else if (t < last_t) c.fail("\"t\" " + std::to_string(t) + " is before the previous event's");
    else last_t = t;
    check_event(j, event, c, fleet, options.strict);
  }
  if (number == 0) errors.push_back("the trace is empty");
  else if (!mission_line) errors.push_back("line " + std::to_string(number) + ": the trace does not end with the mission's end");
  return errors;
}

}  // namespace eamos::trace
