#pragma once
// Running shell commands and reading files for the install tests, which use the installed
// eamos as a user would: through cmake, cpack, dpkg, bash and systemd-analyze.
#include <ifaddrs.h>
#include <net/if.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace eamos_test {

struct Shell {
  int status = -1;
  std::string out;  ///< stdout and stderr together
};

/// Runs `command` with /bin/sh; stdout and stderr together.
inline Shell sh(const std::string& command) {
  Shell r;
  FILE* p = popen(("(" + command + ") 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  int raw = pclose(p);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

/// 'text' for a shell command line.
inline std::string shell_quote(const std::string& text) {
  std::string q = "'";
  for (char c : text) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A fresh folder per test, removed afterwards.
class TempDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("eamos-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "-" +
            std::to_string(getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

/// Installs the build tree (EAMOS_BUILD_DIR) into `prefix` with `cmake --install`.
inline void install_into(const std::filesystem::path& prefix) {
  Shell r = sh(std::string(EAMOS_CMAKE) + " --install " + shell_quote(EAMOS_BUILD_DIR) + " --prefix " +
               shell_quote(prefix.string()));
  ASSERT_EQ(r.status, 0) << r.out;
}

/// An interface that is up, not loopback and has multicast and an IPv4 address, as a drone's
/// WLAN would be; "" when this machine has none.
inline std::string network_interface() {
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return "";
  std::string name;
  for (ifaddrs* a = list; a && name.empty(); a = a->ifa_next)
    if (a->ifa_addr && a->ifa_addr->sa_family == AF_INET && (a->ifa_flags & IFF_UP) &&
        (a->ifa_flags & IFF_MULTICAST) && !(a->ifa_flags & IFF_LOOPBACK))
      name = a->ifa_name;
  freeifaddrs(list);
  return name;
}

}  // namespace eamos_test
