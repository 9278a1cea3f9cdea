// The language server against what an editor (or anything on its standard input) sends: each
// line of the input is one JSON-RPC message handed to the server, as `eamos lsp` hands it a
// frame's body; the same bytes also go through the frame reader, and every frame it finds to
// a second server. Every reply is written as `eamos lsp` writes it.
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "lsp/framing.h"
#include "lsp/server.h"

namespace {

void written(const nlohmann::json& message) {
  (void)message.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

void lines(std::string_view in) {
  eamos::lsp::Server server({});
  std::size_t at = 0;
  while (at < in.size()) {
    std::size_t end = in.find('\n', at);
    if (end == std::string_view::npos) end = in.size();
    if (server.handle(std::string(in.substr(at, end - at)), written)) return;  // exit
    at = end + 1;
  }
}

void frames(std::string_view in) {
  int fd = memfd_create("fuzz_lsp", MFD_CLOEXEC);
  if (fd < 0) return;
  if (write(fd, in.data(), in.size()) == static_cast<ssize_t>(in.size()) && lseek(fd, 0, SEEK_SET) == 0) {
    eamos::lsp::Server server({});
    eamos::lsp::FrameReader reader(fd);
    for (;;) {
      eamos::lsp::Frame f = reader.next();
      if (f.kind == eamos::lsp::Frame::Kind::end) break;
      if (f.kind == eamos::lsp::Frame::Kind::framing_error) {
        written(server.framing_error(f.error));
        continue;
      }
      if (server.handle(f.body, written)) break;
    }
  }
  close(fd);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view in(reinterpret_cast<const char*>(data), size);
  lines(in);
  frames(in);
  return 0;
}
