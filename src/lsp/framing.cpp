#include "lsp/framing.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>

namespace eamos::lsp {

namespace {

constexpr std::size_t kMaxHeaderBytes = 8 * 1024;
constexpr const char* kLengthName = "content-length";

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The end of the header block: the spec asks for CRLF, but a bare LF (a hand-typed session,
// a sloppy client) is accepted too. Returns the header's length and the separator's.
bool find_header_end(const std::string& buffer, std::size_t& header, std::size_t& separator) {
  std::size_t crlf = buffer.find("\r\n\r\n");
  std::size_t lf = buffer.find("\n\n");
  if (crlf == std::string::npos && lf == std::string::npos) return false;
  if (lf != std::string::npos && (crlf == std::string::npos || lf < crlf)) {
    header = lf;
    separator = 2;
  } else {
    header = crlf;
    separator = 4;
  }
  return true;
}

// The Content-Length of a header block; on a bad header, 0 and the reason in `error`.
std::size_t content_length(const std::string& header, std::string& error) {
  std::size_t pos = 0, length = 0;
  bool found = false;
  while (pos <= header.size()) {
    std::size_t eol = header.find('\n', pos);
    if (eol == std::string::npos) eol = header.size();
    std::string line = header.substr(pos, eol - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = eol + 1;
    std::size_t colon = line.find(':');
    if (colon == std::string::npos) {
      if (!line.empty()) error = "header line without ':'";
      continue;
    }
    if (lower(line.substr(0, colon)) != kLengthName) continue;
    std::string value = line.substr(colon + 1);
    while (!value.empty() && value.front() == ' ') value.erase(0, 1);
    while (!value.empty() && (value.back() == ' ' || value.back() == '\t')) value.pop_back();
    if (value.empty() || value.size() > 10 || value.find_first_not_of("0123456789") != std::string::npos) {
      error = "Content-Length is not a number";
      return 0;
    }
    length = std::stoull(value);
    found = true;
  }
  if (!found && error.empty()) error = "no Content-Length header";
  if (found && length > kMaxMessageBytes) error = "Content-Length " + std::to_string(length) + " is over the limit";
  if (found && error.empty()) return length;
  if (error.empty()) error = "bad header";
  return 0;
}

}  // namespace

bool FrameReader::fill() {
  if (eof_) return false;
  char chunk[64 * 1024];
  for (;;) {
    ssize_t n = ::read(fd_, chunk, sizeof chunk);
    if (n > 0) {
      buffer_.append(chunk, static_cast<std::size_t>(n));
      return true;
    }
    if (n < 0 && errno == EINTR) continue;
    eof_ = true;
    return false;
  }
}

// After a bad frame the body (if any) follows, and then, with luck, a good frame: drop
// everything up to the next "Content-Length" so that one bad message costs only itself.
Frame FrameReader::skip_to_next_frame(std::string error) {
  for (;;) {
    std::size_t at = lower(buffer_).find(kLengthName);
    if (at != std::string::npos) {
      buffer_.erase(0, at);
      break;
    }
    // Keep a tail that may be the start of the name split across two reads.
    std::size_t keep = std::min<std::size_t>(buffer_.size(), 14);
    buffer_.erase(0, buffer_.size() - keep);
    if (!fill()) {
      buffer_.clear();
      break;
    }
  }
  return {Frame::Kind::framing_error, "", std::move(error)};
}

Frame FrameReader::next() {
  std::size_t header = 0, separator = 0;
  while (!find_header_end(buffer_, header, separator)) {
    if (buffer_.size() > kMaxHeaderBytes) {
      buffer_.erase(0, 1);  // not at a frame's start: never match this header again
      return skip_to_next_frame("header longer than " + std::to_string(kMaxHeaderBytes) + " bytes");
    }
    if (!fill()) {
      bool blank = buffer_.find_first_not_of(" \t\r\n") == std::string::npos;
      buffer_.clear();
      if (blank) return {Frame::Kind::end, "", ""};
      return {Frame::Kind::framing_error, "", "input ended inside a header"};
    }
  }
  std::string error;
  std::size_t length = content_length(buffer_.substr(0, header), error);
  buffer_.erase(0, header + separator);
  if (!error.empty()) return skip_to_next_frame(error);
  while (buffer_.size() < length) {
    if (!fill()) {
      buffer_.clear();
      return {Frame::Kind::framing_error, "",
              "input ended inside a message (Content-Length " + std::to_string(length) + ")"};
    }
  }
  Frame f{Frame::Kind::message, buffer_.substr(0, length), ""};
  buffer_.erase(0, length);
  return f;
}

bool write_frame(int fd, const nlohmann::json& message) {
  // Replace, not throw, on bytes that are not UTF-8: a diagnostic may quote a broken byte.
  std::string body = message.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string out = "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
  std::size_t done = 0;
  while (done < out.size()) {
    ssize_t n = ::write(fd, out.data() + done, out.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace eamos::lsp
