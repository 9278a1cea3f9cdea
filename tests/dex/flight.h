#pragma once
// Fly a mission text in the simulator on virtual time and keep its trace (tests only).
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "deploy/mission_file.h"
#include "support/mission_edit.h"
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

/// Changes a drone's mission file before its DEX loads it: the way a test builds a mission
/// the checker would refuse (a file on disk is trusted no more than the checker's output).
using MissionEdit = std::function<void(nlohmann::json& mission)>;

inline Flight fly_missions(std::vector<dex::Mission> missions) {
  Flight f;
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

/// Every drone's mission of `text`, each passed through `edit` (if any) before loading.
inline std::vector<dex::Mission> missions_of(const std::string& text, const fleet::Fleet& fleet = {},
                                             const MissionEdit& edit = {}) {
  graph::Compilation c;
  Diagnostics diags;
  if (!graph::compile(std::make_shared<SourceFile>("t.eamos", text), fleet, diags, c)) {
    ADD_FAILURE() << diags.format();
    return {};
  }
  std::vector<dex::Mission> missions;
  std::vector<std::string> errors;
  if (!edit) {  // as `eamos run` loads them
    EXPECT_TRUE(deploy::compiled_missions(c, missions, errors)) << (errors.empty() ? "" : errors.front());
    return missions;
  }
  std::string hash = deploy::mission_hash(c);
  missions.resize(c.drone_count());
  deploy::FleetTables tables;
  for (int d = 0; d < c.drone_count(); ++d) {
    nlohmann::json file = nlohmann::json::parse(deploy::mission_text(c, d, hash));
    edit(file);
    EXPECT_TRUE(deploy::read_mission(eamos_test::sealed(file), c.drone_name(d), missions[d], errors, tables))
        << (errors.empty() ? "" : errors.front());
  }
  return missions;
}

inline Flight fly(const std::string& text, const fleet::Fleet& fleet = {}) {
  std::vector<dex::Mission> missions = missions_of(text, fleet);
  if (missions.empty()) return {};
  return fly_missions(std::move(missions));
}

/// A mission edit: every node `text` (an action, e.g. "A.TakePicture()") becomes a fork,
/// which takes no time. A loop over it is what `eamos check` refuses as a zero-time loop.
inline MissionEdit without_action(const std::string& text) {
  return [text](nlohmann::json& mission) {
    for (auto& n : mission["nodes"])
      if (n.value("text", "") == text) n["kind"] = "fork";
  };
}

inline std::string example(const std::string& name) {
  std::ifstream in(std::string(EAMOS_SOURCE_DIR) + "/examples/" + name);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace eamos::test
