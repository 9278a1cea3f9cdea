#pragma once
// A folder of a test's own under the temporary directory, named after the test's purpose and
// its process, and removed when the test ends, also after a failed ASSERT.
#include <unistd.h>

#include <filesystem>
#include <string>

namespace eamos_test {

struct ScratchDir {
  std::filesystem::path path;
  explicit ScratchDir(const std::string& name)
      : path(std::filesystem::temp_directory_path() / ("eamos-" + name + "-" + std::to_string(getpid()))) {
    std::filesystem::create_directories(path);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  /// The path of `name` inside it.
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

}  // namespace eamos_test
