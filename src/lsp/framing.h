#pragma once
// JSON-RPC 2.0 messages framed as the Language Server Protocol frames them: a header block
// ("Content-Length: N", CRLF-terminated lines, a blank line), then N bytes of JSON. The
// reader never trusts the peer: a bad header, an oversized or truncated frame comes back as
// a framing error with a reason, and the reader finds the next frame instead of stopping.
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

namespace eamos::lsp {

/// A frame larger than this is refused (and skipped): no message of an editor comes close.
constexpr std::size_t kMaxMessageBytes = 64 * 1024 * 1024;

struct Frame {
  enum class Kind { message, framing_error, end };
  Kind kind = Kind::end;
  std::string body;   ///< message: the JSON text
  std::string error;  ///< framing_error: what was wrong
};

class FrameReader {
 public:
  explicit FrameReader(int fd) : fd_(fd) {}
  /// The next frame; `end` once the input is closed and nothing more can be read.
  Frame next();

 private:
  bool fill();  ///< reads more input; false at end of input
  Frame skip_to_next_frame(std::string error);
  int fd_;
  std::string buffer_;
  bool eof_ = false;
};

/// Writes one message with its header; false when the output is closed.
bool write_frame(int fd, const nlohmann::json& message);

}  // namespace eamos::lsp
