#pragma once
// Fly a mission text in the simulator on virtual time and keep its trace (tests only).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "deploy/mission_file.h"
#include "dex/runner.h"
#include "dex/trace_writers.h"
#include "graph/pipeline.h"
#include "sim/sim_adapter.h"

namespace eamos::test {

struct Flight {
  dex::RunResult result;
  std::vector<dex::TraceEvent> events;
  std::string jsonl;

  /// Index of the first event matching, or -1.
  int find(const std::string& event, const std::string& text, const std::string& outcome = "") const {
    for (std::size_t i = 0; i < events.size(); ++i)
      if (events[i].event == event && events[i].text == text && (outcome.empty() || events[i].outcome == outcome))
        return static_cast<int>(i);
    return -1;
  }
  double time_of(const std::string& event, const std::string& text) const {
    int i = find(event, text);
    return i < 0 ? -1.0 : events[i].t;
  }
};

inline Flight fly(const std::string& text, const fleet::Fleet& fleet = {}) {
  graph::Compilation c;
  Diagnostics diags;
  Flight f;
  if (!graph::compile(std::make_shared<SourceFile>("t.eamos", text), fleet, diags, c)) {
    ADD_FAILURE() << diags.format();
    return f;
  }
  std::string hash = deploy::mission_hash(c);
  std::vector<dex::Mission> missions(c.drone_count());
  for (int d = 0; d < c.drone_count(); ++d) {
    std::vector<std::string> errors;
    EXPECT_TRUE(deploy::read_mission(deploy::mission_text(c, d, hash), c.drone_name(d), missions[d], errors))
        << errors.front();
  }
  mid::AdapterRegistry adapters;
  sim::register_adapter(adapters);
  dex::MemoryTrace memory;
  std::ostringstream out;
  dex::JsonlTrace jsonl(out);
  dex::TeeTrace tee;
  tee.add(&memory);
  tee.add(&jsonl);
  dex::RunOptions options;
  options.time_limit_s = 600;
  f.result = dex::run_in_process(missions, adapters, &tee, options);
  f.events = memory.events;
  f.jsonl = out.str();
  return f;
}

inline std::string example(const std::string& name) {
  std::ifstream in(std::string(EAMOS_SOURCE_DIR) + "/examples/" + name);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace eamos::test
