// `eamos monitor` and `--monitor` with bad input, through the real process: a trace is
// untrusted, so every bad line is reported as file:line: error, all at once, exit 1.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "monitor/server.h"
#include "monitor/trace_file.h"
#include "support/run_eamos.h"

namespace {

namespace fs = std::filesystem;

std::string write_temp(const std::string& name, const std::string& text) {
  fs::path p = fs::temp_directory_path() / (std::to_string(getpid()) + "-" + name);
  std::ofstream(p) << text;
  return p.string();
}

TEST(MonitorTrace, EveryBadLineIsReportedWithItsLineNumber) {
  std::string path = write_temp("bad.jsonl",
                                "{\"t\":0,\"drone\":\"Drone1\",\"event\":\"start\",\"name\":\"Arm\",\"line\":3}\n"
                                "not json\n"
                                "{\"t\":\"soon\",\"event\":\"end\"}\n"
                                "[1,2]\n"
                                "{\"t\":1,\"event\":\"end\",\"line\":-4}\n");
  auto r = eamos_test::run_eamos("monitor " + path + " --port 0");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find(path + ":2: error: not valid JSON"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(path + ":3: error: \"t\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(path + ":4: error: a trace line must be a JSON object"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(path + ":5: error: \"line\" must be a whole number"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(":1: error"), std::string::npos) << r.out;
  fs::remove(path);
}

TEST(MonitorTrace, ACutOffLastLineIsAWarningNotAnError) {
  std::istringstream in("{\"t\":0,\"event\":\"start\",\"drone\":\"D\"}\n{\"t\":1,\"ev");
  eamos::monitor::LoadedTrace t = eamos::monitor::read_trace("x.jsonl", in);
  EXPECT_TRUE(t.errors.empty());
  ASSERT_EQ(t.warnings.size(), 1u);
  EXPECT_NE(t.warnings[0].find("x.jsonl:2: warning: the last line is cut off"), std::string::npos);
  EXPECT_EQ(t.events.size(), 1u);
}

TEST(MonitorTrace, AHeaderOfAnotherSchemaVersionIsRefused) {
  std::istringstream in("{\"t\":0,\"event\":\"header\",\"schema\":\"eamos-trace\",\"version\":7}\n");
  eamos::monitor::LoadedTrace t = eamos::monitor::read_trace("x.jsonl", in);
  ASSERT_EQ(t.errors.size(), 1u);
  EXPECT_NE(t.errors[0].find("version 7 is not supported"), std::string::npos) << t.errors[0];
}

TEST(MonitorTrace, UnknownEventsAndFieldsAreKept) {
  std::istringstream in("{\"t\":0.5,\"event\":\"something-new\",\"future\":{\"a\":1}}\n");
  eamos::monitor::LoadedTrace t = eamos::monitor::read_trace("x.jsonl", in);
  EXPECT_TRUE(t.errors.empty());
  ASSERT_EQ(t.events.size(), 1u);
  EXPECT_NE(t.events[0].find("something-new"), std::string::npos);
}

TEST(MonitorEndpoint, HostAndPortAreChecked) {
  eamos::monitor::Endpoint e;
  std::string error;
  EXPECT_TRUE(eamos::monitor::parse_endpoint("8080", e, error));
  EXPECT_EQ(e.host, "127.0.0.1");
  EXPECT_EQ(e.port, 8080);
  EXPECT_TRUE(eamos::monitor::parse_endpoint("0.0.0.0:9000", e, error));
  EXPECT_EQ(e.host, "0.0.0.0");
  EXPECT_FALSE(eamos::monitor::parse_endpoint("70000", e, error));
  EXPECT_NE(error.find("is not a port number"), std::string::npos);
  EXPECT_FALSE(eamos::monitor::parse_endpoint("host;rm:80", e, error));
  EXPECT_FALSE(eamos::monitor::parse_endpoint("", e, error));
}

TEST(MonitorRun, ABadMonitorAddressStopsTheRunBeforeItFlies) {
  auto r = eamos_test::run_eamos("run examples/listing2.eamos -q --monitor 99999");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("error: --monitor '99999' is not a port number"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("Drone1"), std::string::npos) << r.out;
}

}  // namespace
