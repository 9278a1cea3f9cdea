#pragma once
// Reading what a run wrote, for tests: a whole file as text, a JSON file, a JSON Lines trace.
// A file that is not valid JSON throws (nlohmann::json::parse_error), which fails the test
// with the parser's message: the file the run wrote is what is under test.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace eamos_test {

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline nlohmann::json read_json(const std::filesystem::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

/// Every event of a JSONL trace, in order; blank lines skipped.
inline std::vector<nlohmann::json> read_trace(const std::filesystem::path& p) {
  std::vector<nlohmann::json> events;
  std::ifstream in(p);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) events.push_back(nlohmann::json::parse(line));
  return events;
}

}  // namespace eamos_test
