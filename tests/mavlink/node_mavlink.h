#pragma once
// Runs tests/mavlink/node/mavlink_node.js (node-mavlink, an independent MAVLink
// implementation) from a GoogleTest and compares what it decoded with our table. The build
// installs node-mavlink there with `npm ci` (tests/mavlink/CMakeLists.txt); when it could not,
// every cross-check fails saying so instead of passing without having checked anything.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include "mavlink/fields.h"
#include "mavlink/messages.h"

namespace eamos::mavlink::test {

/// What one run of the script printed: its JSON lines, and everything else for the message.
struct NodeRun {
  int exit_code = -1;
  std::vector<nlohmann::json> lines;  ///< decoded frames, then the summary line
  std::string other_output;           ///< stderr and non-JSON lines, for failure messages

  const nlohmann::json& summary() const {
    static const nlohmann::json none;
    return !lines.empty() && lines.back().contains("summary") ? lines.back()["summary"] : none;
  }
  /// Decoded frames only (every line but the summary).
  std::vector<nlohmann::json> frames() const {
    std::vector<nlohmann::json> out;
    for (const auto& l : lines)
      if (!l.contains("summary")) out.push_back(l);
    return out;
  }
};

/// Empty when node-mavlink is installed; otherwise why not and how to fix it.
inline std::string node_mavlink_missing() {
  std::filesystem::path dir = EAMOS_NODE_MAVLINK_DIR;
  if (std::filesystem::exists(dir / "node_modules" / "node-mavlink" / "package.json")) return "";
  return "node-mavlink is not installed in " + dir.string() +
         "/node_modules: the build runs `npm ci` there when CMake finds npm (it found: " +
         std::string(EAMOS_NPM) + "). Install Node.js and npm (scripts/install-deps.sh), " +
         "re-run cmake and build, or run `npm ci` in that folder by hand.";
}

/// Runs `node mavlink_node.js ARGS` and collects its output.
inline NodeRun run_node_mavlink(const std::string& args) {
  NodeRun run;
  std::string command = std::string("'") + EAMOS_NODE + "' '" + EAMOS_NODE_MAVLINK_DIR +
                        "/mavlink_node.js' " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) {
    run.other_output = "popen failed for: " + command;
    return run;
  }
  std::string line;
  for (int c; (c = std::fgetc(pipe)) != EOF;) {
    if (c != '\n') {
      line += static_cast<char>(c);
      continue;
    }
    auto parsed = nlohmann::json::parse(line, nullptr, false);
    if (parsed.is_object()) run.lines.push_back(std::move(parsed));
    else run.other_output += line + "\n";
    line.clear();
  }
  run.other_output += line;
  int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (run.exit_code != 0) run.other_output += "\n(command: " + command + ")";
  return run;
}

/// A scratch folder of its own per test, removed at the end of the test.
class ScratchDir {
 public:
  ScratchDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("eamos-node-" + std::string(info->name()) + "-" + std::to_string(getpid()));
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

inline void write_file(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

inline std::vector<uint8_t> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Element `index` of a field as node-mavlink printed it (the value itself for a scalar).
inline nlohmann::json element(const nlohmann::json& value, int index, const FieldDef& f) {
  return f.array_length ? value.at(static_cast<size_t>(index)) : value;
}

/// A field element of ours as the JSON node-mavlink would print for it.
inline nlohmann::json our_value(const MessageDef& def, const Message& m, const FieldDef& f, int i) {
  FieldReader r(def, m);
  switch (f.type) {
    case FieldType::u8: return r.get<uint8_t>(f.name, i);
    case FieldType::i8: return r.get<int8_t>(f.name, i);
    case FieldType::u16: return r.get<uint16_t>(f.name, i);
    case FieldType::i16: return r.get<int16_t>(f.name, i);
    case FieldType::u32: return r.get<uint32_t>(f.name, i);
    case FieldType::i32: return r.get<int32_t>(f.name, i);
    case FieldType::u64: return std::to_string(r.get<uint64_t>(f.name, i));
    case FieldType::i64: return std::to_string(r.get<int64_t>(f.name, i));
    case FieldType::f32: {
      float v = r.get<float>(f.name, i);
      if (std::isnan(v)) return "NaN";
      if (std::isinf(v)) return v > 0 ? "Infinity" : "-Infinity";
      return static_cast<double>(v);  // exact: node-mavlink widens the float the same way
    }
    case FieldType::f64: {
      double v = r.get<double>(f.name, i);
      if (std::isnan(v)) return "NaN";
      if (std::isinf(v)) return v > 0 ? "Infinity" : "-Infinity";
      return v;
    }
    case FieldType::char_: break;
  }
  return nullptr;  // no char[] field in our table yet; the comparison then fails loudly
}

/// Expects node-mavlink's decoded `fields` to hold every field of `m` with the same value.
inline void expect_same_fields(const MessageDef& def, const Message& m,
                               const nlohmann::json& node_fields, const std::string& where) {
  for (const FieldDef& f : def.fields) {
    ASSERT_TRUE(node_fields.contains(f.name))
        << where << ": node-mavlink has no field " << def.name << "." << f.name;
    const nlohmann::json& theirs = node_fields[std::string(f.name)];
    if (f.type == FieldType::char_) {
      // node-mavlink gives a char[N] as a string, cut at the first NUL, as we read it.
      EXPECT_EQ(theirs, FieldReader(def, m).get_chars(f.name)) << where << ": " << def.name << "." << f.name;
      continue;
    }
    for (int i = 0; i < std::max<int>(1, f.array_length); ++i) {
      EXPECT_EQ(element(theirs, i, f), our_value(def, m, f, i))
          << where << ": " << def.name << "." << f.name
          << (f.array_length ? "[" + std::to_string(i) + "]" : "");
    }
  }
}

}  // namespace eamos::mavlink::test
