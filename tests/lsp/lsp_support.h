#pragma once
// Runs the real `eamos lsp` (EAMOS_BINARY) on a whole recorded session: the client's
// messages framed into a file that becomes its standard input, its standard output read
// back as frames. The server answers in the order it reads, on one thread, so a session's
// transcript depends only on its input: no waiting, no timing.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

namespace eamos_test {

inline std::string frame(const std::string& body) {
  return "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
}

struct LspRun {
  int status = -1;                       ///< exit status; -1 when killed by a signal
  std::vector<nlohmann::json> messages;  ///< what the server wrote, in order
  std::string problem;                   ///< a framing fault of the server's output; "" when none
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Splits the server's output into messages, strictly: any byte out of frame is a fault.
inline void read_frames(const std::string& out, LspRun& run) {
  std::size_t pos = 0;
  while (pos < out.size()) {
    const std::string prefix = "Content-Length: ";
    std::size_t end = out.find("\r\n\r\n", pos);
    if (out.compare(pos, prefix.size(), prefix) != 0 || end == std::string::npos) {
      run.problem = "output not framed at byte " + std::to_string(pos) + ": " + out.substr(pos, 80);
      return;
    }
    std::size_t length = std::stoul(out.substr(pos + prefix.size(), end - pos - prefix.size()));
    pos = end + 4;
    nlohmann::json j = nlohmann::json::parse(out.substr(pos, length), nullptr, false);
    if (j.is_discarded() || pos + length > out.size()) {
      run.problem = "a frame's body is not JSON: " + out.substr(pos, 200);
      return;
    }
    run.messages.push_back(std::move(j));
    pos += length;
  }
}

/// Runs `eamos lsp args...` with `input` (already framed) as its standard input.
inline LspRun run_lsp(const std::vector<std::string>& args, const std::string& input) {
  LspRun run;
  char in_path[] = "/tmp/eamos-lsp-in-XXXXXX";
  char out_path[] = "/tmp/eamos-lsp-out-XXXXXX";
  int in_fd = mkstemp(in_path), out_fd = mkstemp(out_path);
  if (in_fd < 0 || out_fd < 0) return run;
  if (::write(in_fd, input.data(), input.size()) != static_cast<ssize_t>(input.size())) return run;
  lseek(in_fd, 0, SEEK_SET);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in_fd, STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, out_fd, STDOUT_FILENO);
  std::vector<std::string> all = {EAMOS_BINARY, "lsp"};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  if (posix_spawn(&pid, EAMOS_BINARY, &actions, nullptr, argv.data(), environ) == 0) {
    int raw = 0;
    if (waitpid(pid, &raw, 0) == pid && WIFEXITED(raw)) run.status = WEXITSTATUS(raw);
  }
  posix_spawn_file_actions_destroy(&actions);
  close(in_fd);
  close(out_fd);
  read_frames(slurp(out_path), run);
  std::remove(in_path);
  std::remove(out_path);
  return run;
}

}  // namespace eamos_test
