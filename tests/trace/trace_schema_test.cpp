// The trace schema (docs/trace.md): every example's trace, as the real `eamos run` writes
// it, keeps it event by event; and the check itself refuses what breaks it (a check that
// passes everything would prove nothing). Distributed traces are checked in
// tests/launch/distributed_test.cpp, MAVLink ones in tests/mavlink_adapter/listing2_test.cpp.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "trace/trace_schema.h"
#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> errors_of(const std::string& text) {
  std::istringstream in(text);
  return eamos::trace::check_trace(in, {.strict = true});
}

std::string joined(const std::vector<std::string>& v) {
  std::string all;
  for (const std::string& s : v) all += s + "\n";
  return all;
}

std::vector<nlohmann::json> lines_of(const std::string& text) {
  std::vector<nlohmann::json> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(nlohmann::json::parse(line));
  return out;
}

class TraceSchema : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eamos-trace-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  /// The trace of `eamos run` of `mission` (an examples/ file) with `extra` arguments.
  std::string trace_of(const std::string& mission, const std::string& extra = "") {
    fs::path trace = dir_ / (mission + ".jsonl");
    eamos_test::Output r = eamos_test::run_eamos("run -q " + std::string(EAMOS_SOURCE_DIR) + "/examples/" + mission +
                                                 " " + extra + " --trace " + trace.string());
    EXPECT_EQ(r.status, 0) << r.out;
    return read_file(trace);
  }
  fs::path dir_;
};

TEST_F(TraceSchema, EveryExampleTraceKeepsTheSchemaEventByEvent) {
  int examples = 0;
  for (const auto& entry : fs::directory_iterator(std::string(EAMOS_SOURCE_DIR) + "/examples")) {
    if (entry.path().extension() != ".eamos") continue;
    ++examples;
    std::string name = entry.path().filename().string();
    std::string trace = trace_of(name);
    EXPECT_EQ(joined(errors_of(trace)), "") << name;
    // Not an empty shell: the header embeds the mission text, actions name their MEG node,
    // drones are sampled and, with several drones, triggers cross between them.
    std::vector<nlohmann::json> lines = lines_of(trace);
    ASSERT_GE(lines.size(), 3u) << name;
    EXPECT_EQ(lines.front()["source"], read_file(entry.path())) << name;
    EXPECT_EQ(lines.front()["telemetry_hz"], 5.0) << name;
    int telemetry = 0, messages = 0, actions = 0, inits = 0;
    for (const nlohmann::json& e : lines) {
      telemetry += e["event"] == "telemetry";
      messages += e["event"] == "message";
      // In one process a message takes no time.
      if (e["event"] == "message") {
        EXPECT_EQ(e["latency"], 0.0) << name << ": " << e.dump();
      }
      actions += e["event"] == "start" && e.contains("node");
      inits += e["event"] == "node" && e["kind"] == "init" && e.contains("instance");  // one clone per drone
    }
    EXPECT_GT(telemetry, 0) << name;
    EXPECT_GT(actions, 0) << name;
    EXPECT_GE(inits, 1) << name;
    if (lines.front()["drones"].size() > 1) {
      EXPECT_GT(messages, 0) << name;
    }
  }
  EXPECT_GE(examples, 4);
}

TEST_F(TraceSchema, TheFleetTextIsEmbeddedAndTelemetryFollowsTheRequestedRate) {
  std::string fleet = std::string(EAMOS_SOURCE_DIR) + "/examples/listing2-right.yaml";
  std::vector<nlohmann::json> lines = lines_of(trace_of("listing2.eamos", "--fleet " + fleet + " --telemetry-hz 2"));
  EXPECT_EQ(lines.front()["fleet"], read_file(fleet));
  EXPECT_EQ(lines.front()["telemetry_hz"], 2.0);
  for (const nlohmann::json& e : lines)
    if (e["event"] == "telemetry") {
      double slots = e["t"].get<double>() * 2;
      EXPECT_NEAR(slots, std::round(slots), 1e-6) << e.dump();
    }
}

TEST_F(TraceSchema, RateZeroWritesNoTelemetry) {
  std::string trace = trace_of("listing2.eamos", "--telemetry-hz 0");
  EXPECT_EQ(trace.find("\"event\":\"telemetry\""), std::string::npos);
  EXPECT_EQ(joined(errors_of(trace)), "");
}

// --- the check refuses broken traces ---------------------------------------------------

const std::string kHeader =
    R"({"t":0,"event":"header","schema":"eamos-trace","version":1,"mission":"m.eamos","mission_hash":"ab",)"
    R"("source":"","fleet":"","drones":[{"name":"D1","index":0,"type":"T","home":[0,0,0]}],"telemetry_hz":5})";
const std::string kStart = R"({"t":1,"drone":"D1","event":"start","name":"Arm","line":3,"node":2})";
const std::string kEnd = R"({"t":1,"drone":"","event":"mission","name":"","line":0,"outcome":"completed"})";

TEST(TraceCheck, AcceptsAWellFormedTrace) { EXPECT_EQ(joined(errors_of(kHeader + "\n" + kStart + "\n" + kEnd + "\n")), ""); }

TEST(TraceCheck, RefusesALineThatIsNotJson) {
  std::vector<std::string> e = errors_of(kHeader + "\n{\"t\":1,\n" + kEnd + "\n");
  ASSERT_EQ(e.size(), 1u) << joined(e);
  EXPECT_EQ(e[0], "line 2: not a JSON object");
}

TEST(TraceCheck, RefusesATraceWithoutItsHeaderFirst) {
  EXPECT_EQ(joined(errors_of(kStart + "\n" + kEnd + "\n")), "line 1: the first line is not the header\n");
}

TEST(TraceCheck, RefusesATraceThatDoesNotEndWithTheMission) {
  EXPECT_EQ(joined(errors_of(kHeader + "\n" + kStart + "\n")), "line 2: the trace does not end with the mission's end\n");
  EXPECT_EQ(joined(errors_of(kHeader + "\n" + kEnd + "\n" + kStart + "\n")),
            "line 3: an event after the mission's end (line 2)\n");
}

TEST(TraceCheck, RefusesAnActionEventWithoutItsNodeOrWithAWrongType) {
  std::string no_node = R"({"t":1,"drone":"D1","event":"start","name":"Arm","line":3})";
  EXPECT_EQ(joined(errors_of(kHeader + "\n" + no_node + "\n" + kEnd + "\n")),
            "line 2: missing \"node\", an integer of at least 0\n");
  std::string text_line = R"({"t":1,"drone":"D1","event":"start","name":"Arm","line":"3","node":2})";
  EXPECT_EQ(joined(errors_of(kHeader + "\n" + text_line + "\n" + kEnd + "\n")),
            "line 2: \"line\" is not an integer of at least 0\n");
}

TEST(TraceCheck, RefusesAnUnknownDroneOutcomeOrEventKind) {
  std::string stranger = R"({"t":1,"drone":"D9","event":"start","name":"Arm","line":3,"node":2})";
  std::string outcome = R"({"t":1,"drone":"D1","event":"end","name":"Arm","line":3,"node":2,"outcome":"fine"})";
  std::string kind = R"({"t":1,"drone":"D1","event":"party"})";
  std::vector<std::string> e = errors_of(kHeader + "\n" + stranger + "\n" + outcome + "\n" + kind + "\n" + kEnd + "\n");
  EXPECT_EQ(joined(e),
            "line 2: \"drone\" names \"D9\", which is not a drone of the header\n"
            "line 3: \"outcome\" is \"fine\", not one of the schema's values\n"
            "line 4: event \"party\" is not defined by schema version 1\n");
  // A reader (not strict) skips kinds it does not know: a newer eamos may add some.
  std::istringstream in(kHeader + "\n" + kind + "\n" + kEnd + "\n");
  EXPECT_TRUE(eamos::trace::check_trace(in).empty());
}

TEST(TraceCheck, AViolationNeedsItsDroneKindLineAndText) {
  std::string good = R"({"t":1,"event":"violation","drone":"D1","kind":"separation","line":3,"text":"too close","drones":["D1"]})";
  EXPECT_EQ(joined(errors_of(kHeader + "\n" + good + "\n" + kEnd + "\n")), "");
  std::string bare = R"({"t":1,"event":"violation","drone":"D1"})";
  std::string wrong = R"({"t":1,"event":"violation","drone":"D1","kind":"rudeness","line":3,"text":"x","drones":["D9"]})";
  EXPECT_EQ(joined(errors_of(kHeader + "\n" + bare + "\n" + wrong + "\n" + kEnd + "\n")),
            "line 2: missing \"kind\", a string\n"
            "line 2: missing \"line\", an integer of at least 0\n"
            "line 2: missing \"text\", a string\n"
            "line 3: \"kind\" is \"rudeness\", not one of the schema's values\n"
            "line 3: \"drones\" is not a list of drones of the header\n");
}

TEST(TraceCheck, RefusesBrokenTelemetryAndMessages) {
  std::string telemetry = R"({"t":1,"event":"telemetry","drone":"D1","x":0,"y":"0","z":0,"heading":400,)"
                          R"("armed":true,"landed":false,"battery":90,"mode":"go"})";
  std::string message = R"({"t":1,"event":"message","drone":"D1","kind":"trigger","from":"D1","to":"D1",)"
                        R"("node":4,"sent":2,"received":1})";
  EXPECT_EQ(joined(errors_of(kHeader + "\n" + telemetry + "\n" + message + "\n" + kEnd + "\n")),
            "line 2: \"y\" is not a finite number\n"
            "line 2: \"heading\" is neither null nor degrees from 0 to 360\n"
            "line 3: received before it was sent\n");
}

TEST(TraceCheck, AMessagesLatencyIsItsReceivedMinusSentTime) {
  std::string message = R"({"t":1.25,"event":"message","drone":"D1","kind":"trigger","from":"D1","to":"D1",)"
                        R"("node":4,"sent":1,"received":1.25,)";
  std::string end = R"({"t":2,"drone":"","event":"mission","name":"","line":0,"outcome":"completed"})";
  EXPECT_EQ(joined(errors_of(kHeader + "\n" + message + R"("latency":0.25})" + "\n" + end + "\n")), "");
  // Older traces have none: the field was added within version 1.
  EXPECT_EQ(joined(errors_of(kHeader + "\n" + message.substr(0, message.size() - 1) + "}\n" + end + "\n")), "");
  EXPECT_EQ(joined(errors_of(kHeader + "\n" + message + R"("latency":"0.25"})" + "\n" + message +
                             R"("latency":0.5})" + "\n" + message + R"("latency":-0.25})" + "\n" + end + "\n")),
            "line 2: \"latency\" is not a finite number\n"
            "line 3: \"latency\" is not \"received\" - \"sent\"\n"
            "line 4: \"latency\" is negative\n");
}

TEST(TraceCheck, RefusesANodeEventOfAnUnknownKindOrOutcome) {
  std::string node = R"({"t":1,"drone":"D1","event":"node","name":"PAR_x","line":3,"node":1,"kind":"knot","outcome":"ended"})";
  std::string outcome = R"({"t":1,"drone":"D1","event":"node","name":"PAR_x","line":3,"node":1,"kind":"fork","outcome":"gone"})";
  EXPECT_EQ(joined(errors_of(kHeader + "\n" + node + "\n" + outcome + "\n" + kEnd + "\n")),
            "line 2: \"kind\" is \"knot\", not one of the schema's values\n"
            "line 3: \"outcome\" is \"gone\", not one of the schema's values\n");
}

TEST(TraceCheck, RefusesEventsOutOfTimeOrder) {
  std::string later = R"({"t":2,"drone":"D1","event":"start","name":"Arm","line":3,"node":2})";
  EXPECT_EQ(joined(errors_of(kHeader + "\n" + later + "\n" + kStart + "\n" + kEnd + "\n")),
            "line 3: \"t\" 1.000000 is before the previous event's\n");
}

TEST_F(TraceSchema, ARealTraceWithOneFieldBrokenFails) {
  std::string trace = trace_of("relay.eamos");
  std::size_t at = trace.find("\"event\":\"start\"");
  ASSERT_NE(at, std::string::npos);
  std::size_t node = trace.find("\"node\":", at);
  trace.replace(node, 7, "\"node\":-");  // a negative node id
  EXPECT_FALSE(errors_of(trace).empty());
}

}  // namespace
