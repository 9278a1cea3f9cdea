#pragma once
// Raw TCP clients of the monitor, for the tests that play a misbehaving browser: one that
// stops reading, one that sends half a request, and a well-behaved WebSocket page that reads
// every message and answers pings as a browser does. Every wait has a deadline (poll), never
// a sleep.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <string>

namespace eamos_test {

using Deadline = std::chrono::steady_clock::time_point;
inline Deadline after(double seconds) {
  return std::chrono::steady_clock::now() +
         std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
}

class RawClient {
 public:
  RawClient() = default;
  RawClient(const RawClient&) = delete;
  RawClient& operator=(const RawClient&) = delete;
  RawClient(RawClient&& o) noexcept : fd_(o.fd_), in_(std::move(o.in_)) { o.fd_ = -1; }
  ~RawClient() { close_now(); }

  /// Connects to 127.0.0.1:port. `slow_link`: a small receive buffer and segments of 536
  /// bytes, as over a poor link; the server's kernel then sizes its send buffer for this
  /// connection at tens of kB instead of the MBs of a loopback one, so a client that stops
  /// reading blocks the server's writes within the first megabyte.
  bool connect_to(int port, bool slow_link = false) {
    fd_ = socket(AF_INET, SOCK_STREAM, 0);
    if (fd_ < 0) return false;
    if (slow_link) {
      int buffer = 4096, segment = 536;
      setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &buffer, sizeof buffer);
      setsockopt(fd_, IPPROTO_TCP, TCP_MAXSEG, &segment, sizeof segment);
    }
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<uint16_t>(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    return connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
  }

  bool send_all(const std::string& data) {
    std::size_t done = 0;
    while (done < data.size()) {
      ssize_t n = send(fd_, data.data() + done, data.size() - done, MSG_NOSIGNAL);
      if (n <= 0) return false;
      done += static_cast<std::size_t>(n);
    }
    return true;
  }

  /// The WebSocket upgrade of /ws, as a page of http://127.0.0.1:port would send it; true on 101.
  bool websocket_handshake(int port, Deadline until) {
    std::string host = "127.0.0.1:" + std::to_string(port);
    if (!send_all("GET /ws HTTP/1.1\r\nHost: " + host + "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                  "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\nOrigin: http://" +
                  host + "\r\n\r\n"))
      return false;
    std::string head;
    if (!read_until(head, "\r\n\r\n", until)) return false;
    return head.rfind("HTTP/1.1 101", 0) == 0;
  }

  /// Sends a text frame, masked as a client must.
  bool send_text(const std::string& text) { return send_frame(0x1, text); }

  /// The next text message, answering pings on the way; false on a deadline, close or error.
  bool next_text(std::string& text, Deadline until) {
    for (;;) {
      int opcode = 0;
      std::string payload;
      if (!read_frame(opcode, payload, until)) return false;
      if (opcode == 0x9) {
        if (!send_frame(0xA, payload)) return false;
      } else if (opcode == 0x8) {
        return false;
      } else if (opcode == 0x1) {
        text = std::move(payload);
        return true;
      }
    }
  }

  /// Everything until the server closes the connection; false on the deadline.
  bool read_all(std::string& out, Deadline until) {
    char buf[65536];
    out = std::move(in_);
    in_.clear();
    for (;;) {
      if (!wait_readable(until)) return false;
      ssize_t n = recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) return true;
      out.append(buf, static_cast<std::size_t>(n));
    }
  }

  /// Reads and discards until the server closes the connection (true) or the deadline passes.
  bool closed_by_server(Deadline until) {
    char buf[65536];
    for (;;) {
      if (!wait_readable(until)) return false;
      ssize_t n = recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) return true;
    }
  }

  void close_now() {
    if (fd_ >= 0) close(fd_);
    fd_ = -1;
  }

 private:
  bool wait_readable(Deadline until) {
    for (;;) {
      auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now()).count();
      if (left <= 0) return false;
      pollfd p{fd_, POLLIN, 0};
      int r = poll(&p, 1, static_cast<int>(left));
      if (r > 0) return true;
      if (r < 0 && errno != EINTR) return false;
    }
  }

  // Appends what arrives to in_ until it holds `n` bytes.
  bool fill(std::size_t n, Deadline until) {
    char buf[65536];
    while (in_.size() < n) {
      if (!wait_readable(until)) return false;
      ssize_t got = recv(fd_, buf, sizeof buf, 0);
      if (got <= 0) return false;
      in_.append(buf, static_cast<std::size_t>(got));
    }
    return true;
  }

  bool read_until(std::string& out, const std::string& end, Deadline until) {
    std::size_t at;
    while ((at = in_.find(end)) == std::string::npos)
      if (!fill(in_.size() + 1, until)) return false;
    out = in_.substr(0, at + end.size());
    in_.erase(0, at + end.size());
    return true;
  }

  bool read_frame(int& opcode, std::string& payload, Deadline until) {
    if (!fill(2, until)) return false;
    opcode = static_cast<unsigned char>(in_[0]) & 0x0f;
    std::uint64_t length = static_cast<unsigned char>(in_[1]) & 0x7f;
    std::size_t header = 2;
    if (length == 126 || length == 127) {
      header = length == 126 ? 4 : 10;
      if (!fill(header, until)) return false;
      length = 0;
      for (std::size_t i = 2; i < header; ++i) length = (length << 8) | static_cast<unsigned char>(in_[i]);
    }
    if (!fill(header + length, until)) return false;
    payload = in_.substr(header, length);
    in_.erase(0, header + length);
    return true;
  }

  bool send_frame(int opcode, const std::string& data) {
    std::string frame(1, static_cast<char>(0x80 | opcode));
    const unsigned char mask[4] = {0x12, 0x34, 0x56, 0x78};
    if (data.size() < 126) {
      frame += static_cast<char>(0x80 | data.size());
    } else {
      frame += static_cast<char>(0x80 | 126);
      frame += static_cast<char>((data.size() >> 8) & 0xff);
      frame += static_cast<char>(data.size() & 0xff);
    }
    frame.append(reinterpret_cast<const char*>(mask), 4);
    for (std::size_t i = 0; i < data.size(); ++i) frame += static_cast<char>(data[i] ^ mask[i % 4]);
    return send_all(frame);
  }

  int fd_ = -1;
  std::string in_;
};

}  // namespace eamos_test
