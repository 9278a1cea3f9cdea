#include "mavlink/link.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "diag/log.h"

namespace eamos::mavlink {

namespace {

// From the catch handlers of the receive thread: nothing may leave it, not even a bad_alloc.
void report(diag::LogLevel level, std::string_view before, const std::string& url, std::string_view after,
            const char* what) noexcept {
  try {
    std::string text = std::string(before) + url + std::string(after);
    if (what) (text += ": ") += what;
    diag::log(level, "mavlink", "", text);
  } catch (...) {
  }
}

std::string sys_error(const std::string& what) { return what + ": " + std::strerror(errno); }

/// Resolves an IPv4 address; "" means every local address.
bool resolve(const std::string& host, uint16_t port, sockaddr_in& out, std::string& error) {
  out = {};
  out.sin_family = AF_INET;
  out.sin_port = htons(port);
  if (host.empty()) {
    out.sin_addr.s_addr = htonl(INADDR_ANY);
    return true;
  }
  if (inet_pton(AF_INET, host.c_str(), &out.sin_addr) == 1) return true;
  addrinfo hints{};
  hints.ai_family = AF_INET;
  addrinfo* found = nullptr;
  if (int rc = getaddrinfo(host.c_str(), nullptr, &hints, &found); rc != 0 || !found) {
    error = "cannot resolve host '" + host + "': " + gai_strerror(rc);
    return false;
  }
  out.sin_addr = reinterpret_cast<sockaddr_in*>(found->ai_addr)->sin_addr;
  freeaddrinfo(found);
  return true;
}

/// Connects with a bound wait, so an unreachable autopilot is an error, not a hang.
bool connect_within(int fd, const sockaddr_in& to, int timeout_ms, std::string& error) {
  int flags = fcntl(fd, F_GETFL, 0);
  fcntl(fd, F_SETFL, flags | O_NONBLOCK);
  int rc = connect(fd, reinterpret_cast<const sockaddr*>(&to), sizeof to);
  if (rc != 0 && errno != EINPROGRESS) {
    error = sys_error("connect");
    return false;
  }
  if (rc != 0) {
    pollfd p{fd, POLLOUT, 0};
    if (poll(&p, 1, timeout_ms) != 1) {
      error = "connect: no answer within " + std::to_string(timeout_ms / 1000) + " s";
      return false;
    }
    int so_error = 0;
    socklen_t len = sizeof so_error;
    getsockopt(fd, SOL_SOCKET, SO_ERROR, &so_error, &len);
    if (so_error != 0) {
      error = std::string("connect: ") + std::strerror(so_error);
      return false;
    }
  }
  fcntl(fd, F_SETFL, flags);
  return true;
}

speed_t termios_speed(unsigned baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 500000: return B500000;
    case 576000: return B576000;
    case 921600: return B921600;
    case 1000000: return B1000000;
    case 1500000: return B1500000;
    case 2000000: return B2000000;
    default: return B3000000;  // parse_link_url lets no other rate through
  }
}

/// Opens a serial port raw (8N1, no flow control, no echo, no line discipline) at `baud`,
/// non-blocking; -1 with `error` when it is no serial port or cannot be set so. Exclusive
/// (TIOCEXCL): a second program opening the port would take half of the autopilot's bytes.
int open_serial(const fleet::Endpoint& e, std::string& error) {
  int fd = ::open(e.device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    error = sys_error("open " + e.device);
    return -1;
  }
  struct stat st {};
  termios tio{};
  if (fstat(fd, &st) != 0 || !S_ISCHR(st.st_mode) || tcgetattr(fd, &tio) != 0) {
    error = e.device + " is not a serial port";
    close(fd);
    return -1;
  }
  cfmakeraw(&tio);
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_cflag &= ~(CSTOPB | CRTSCTS);
  tio.c_cc[VMIN] = 1;
  tio.c_cc[VTIME] = 0;
  if (cfsetispeed(&tio, termios_speed(e.baud)) != 0 || cfsetospeed(&tio, termios_speed(e.baud)) != 0 ||
      tcsetattr(fd, TCSANOW, &tio) != 0 || ioctl(fd, TIOCEXCL) != 0) {
    error = sys_error("set " + e.device + " to " + std::to_string(e.baud) + " baud");
    close(fd);
    return -1;
  }
  tcflush(fd, TCIOFLUSH);  // what an earlier program left unread is no frame of this link
  // It stays non-blocking: a port whose other end stopped reading (a hung autopilot, a USB
  // bridge) fills its buffer, and a blocking write would stall the event loop that sends.
  // The frame is then dropped (send() is false); reads wait in poll().
  return fd;
}

/// A bound socket (udp://, udpout://) or a connected one (tcp://); -1 with `error`.
int open_socket(const fleet::Endpoint& endpoint, const sockaddr_in& addr, std::string& error) {
  bool tcp = endpoint.kind == fleet::LinkKind::tcp_client;
  int fd = socket(AF_INET, tcp ? SOCK_STREAM : SOCK_DGRAM, 0);
  if (fd < 0) {
    error = sys_error("socket");
    return -1;
  }
  if (endpoint.kind == fleet::LinkKind::udp_listen) {
    // No SO_REUSEADDR: on Linux it would let a second program share the port and steal
    // half of the vehicle's datagrams; a clear "in use" error is better.
    if (bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
      error = sys_error("bind to port " + std::to_string(endpoint.port)) + " (is another program listening there?)";
      close(fd);
      return -1;
    }
  } else if (endpoint.kind == fleet::LinkKind::udp_out) {
    sockaddr_in any{};
    any.sin_family = AF_INET;  // port 0: an ephemeral port, where the replies come back
    if (bind(fd, reinterpret_cast<sockaddr*>(&any), sizeof any) != 0) {
      error = sys_error("bind");
      close(fd);
      return -1;
    }
  } else if (!connect_within(fd, addr, 5000, error)) {
    error += " (is the autopilot or SITL serving TCP there?)";
    close(fd);
    return -1;
  }
  return fd;
}

}  // namespace

OpenResult Link::open(const fleet::Endpoint& endpoint, FrameHandler on_frame, double reconnect_s,
                      const std::optional<SigningKey>& verify, bool require_signed) {
  auto fail = [&](const std::string& why) {
    return OpenResult{nullptr, "connection '" + endpoint.url + "': " + why};
  };
  bool serial = endpoint.kind == fleet::LinkKind::serial;
  sockaddr_in addr{};
  std::string error;
  if (!serial && !resolve(endpoint.host, endpoint.port, addr, error)) return fail(error);
  int fd = serial ? open_serial(endpoint, error) : open_socket(endpoint, addr, error);
  if (fd < 0) return fail(error);
  int pipe_fds[2];
  if (pipe(pipe_fds) != 0) {
    close(fd);
    return fail(sys_error("pipe"));
  }
  std::unique_ptr<Link> link(new Link(endpoint, fd, pipe_fds[0], pipe_fds[1], std::move(on_frame)));
  link->reconnect_ms_ = static_cast<int>(reconnect_s * 1000.0);
  if (verify) {  // before the receive thread exists: no datagram is read without the key
    link->parser_.verify_with(*verify);
    link->parser_.require_signed(require_signed);
  }
  if (endpoint.kind != fleet::LinkKind::udp_listen) {
    link->peer_ = addr;  // serial: unused; the port itself is the peer
    link->has_peer_ = true;
  }
  link->thread_ = std::thread([l = link.get()] {
    // An exception leaving a thread ends the process (std::terminate), and with it the
    // vehicle's link in mid-flight; receive_loop drops a bad datagram itself, this is the last net.
    try {
      l->receive_loop();
    } catch (const std::exception& e) {
      report(diag::LogLevel::error, "MAVLink receive thread of '", l->endpoint_.url, "' stopped", e.what());
    } catch (...) {
      report(diag::LogLevel::error, "MAVLink receive thread of '", l->endpoint_.url, "' stopped", nullptr);
    }
  });
  return {std::move(link), ""};
}

Link::Link(fleet::Endpoint endpoint, int fd, int wake_read, int wake_write, FrameHandler on_frame)
    : endpoint_(std::move(endpoint)),
      fd_(fd),
      wake_read_(wake_read),
      wake_write_(wake_write),
      on_frame_(std::move(on_frame)) {
  sockaddr_in local{};
  socklen_t len = sizeof local;
  if (getsockname(fd_, reinterpret_cast<sockaddr*>(&local), &len) == 0)
    local_port_ = ntohs(local.sin_port);
}

Link::~Link() {
  if (thread_.joinable()) {
    char byte = 1;
    [[maybe_unused]] ssize_t n = write(wake_write_, &byte, 1);
    thread_.join();
  }
  for (int fd : {fd_, wake_read_, wake_write_})
    if (fd >= 0) close(fd);
}

bool Link::send(std::span<const uint8_t> bytes) {
  std::lock_guard lock(mutex_);
  if (!has_peer_ || closed_) return false;
  ssize_t n = endpoint_.kind == fleet::LinkKind::tcp_client ? ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL)
              : endpoint_.kind == fleet::LinkKind::serial   ? ::write(fd_, bytes.data(), bytes.size())
                                                     : sendto(fd_, bytes.data(), bytes.size(), 0,
                                                              reinterpret_cast<const sockaddr*>(&peer_), sizeof peer_);
  return n == static_cast<ssize_t>(bytes.size());
}

ParserStats Link::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

void Link::receive_loop() {
  std::vector<uint8_t> buffer(65536);
  for (;;) {
    pollfd fds[2] = {{fd_, POLLIN, 0}, {wake_read_, POLLIN, 0}};
    if (poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      return;
    }
    if (fds[1].revents != 0) return;  // the destructor wants us gone
    if (fds[0].revents == 0) continue;
    sockaddr_in from{};
    socklen_t from_len = sizeof from;
    bool stream = endpoint_.kind == fleet::LinkKind::tcp_client || endpoint_.kind == fleet::LinkKind::serial;
    ssize_t n = endpoint_.kind == fleet::LinkKind::serial
                    ? ::read(fd_, buffer.data(), buffer.size())
                    : recvfrom(fd_, buffer.data(), buffer.size(), 0, reinterpret_cast<sockaddr*>(&from), &from_len);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) {
      if (!stream) continue;     // UDP: e.g. ICMP port unreachable
      if (!reconnect()) return;  // the destructor came first
      continue;
    }
    bool listen = endpoint_.kind == fleet::LinkKind::udp_listen;
    try {
      handle_bytes(std::span(buffer.data(), static_cast<size_t>(n)), listen ? &from : nullptr);
    } catch (const std::exception& e) {  // drop this datagram, keep the link
      report(diag::LogLevel::warning, "dropped MAVLink input from '", endpoint_.url, "'", e.what());
    } catch (...) {
      report(diag::LogLevel::warning, "dropped MAVLink input from '", endpoint_.url, "'", nullptr);
    }
  }
}

bool Link::reconnect() {
  // The TCP peer hung up (a SITL restarted, a radio dropped out), or the serial port went
  // away (a USB autopilot unplugged or rebooted). Heartbeats stop meanwhile, so the adapter
  // sees a lost link; try again until it is back.
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
    close(fd_);
    fd_ = -1;
  }
  parser_ = Parser{};  // half a frame from the old connection must not join the new one
  for (;;) {
    pollfd wake{wake_read_, POLLIN, 0};
    if (poll(&wake, 1, reconnect_ms_) != 0) return false;
    std::string error;
    int fd = endpoint_.kind == fleet::LinkKind::serial ? open_serial(endpoint_, error) : socket(AF_INET, SOCK_STREAM, 0);
    if (fd >= 0 && (endpoint_.kind == fleet::LinkKind::serial || connect_within(fd, peer_, 1000, error))) {
      std::lock_guard lock(mutex_);
      fd_ = fd;
      closed_ = false;
      return true;
    }
    if (fd >= 0) close(fd);
  }
}

namespace {
bool same_address(const sockaddr_in& a, const sockaddr_in& b) {
  return a.sin_addr.s_addr == b.sin_addr.s_addr && a.sin_port == b.sin_port;
}
}  // namespace

void Link::verify_with(SigningKey key, bool required) {
  std::lock_guard lock(mutex_);
  pending_key_ = key;
  pending_required_ = required;
}

void Link::require_signed(bool required) {
  std::lock_guard lock(mutex_);
  pending_required_ = required;
}

void Link::handle_bytes(std::span<const uint8_t> bytes, const sockaddr_in* from) {
  {
    std::lock_guard lock(mutex_);
    if (pending_key_) parser_.verify_with(*pending_key_);
    if (pending_required_) parser_.require_signed(*pending_required_);
    pending_key_.reset();
    pending_required_.reset();
  }
  if (from && locked_) {
    bool vehicle;
    {
      std::lock_guard lock(mutex_);
      vehicle = same_address(*from, peer_);
    }
    if (!vehicle) {  // not the vehicle's address: not even parsed
      ++foreign_datagrams_;
      return;
    }
  }
  if (from && !same_address(*from, last_from_)) {
    parser_.discard_partial();
    last_from_ = *from;
  }
  std::vector<Frame> frames = parser_.feed(bytes);
  if (from) follow_sender(frames, *from);
  {
    std::lock_guard lock(mutex_);
    stats_ = parser_.stats();
  }
  for (Frame& f : frames) on_frame_(std::move(f));
}

// Replies go where the vehicle is, as PX4's offboard link expects, and the vehicle is
// where its first valid frame came from: anybody can send a datagram to the port, and
// anybody can forge a CRC-checked frame with the vehicle's system id (the CRC is no
// secret), so once the vehicle is known its address is kept. A vehicle that comes back on
// another port (a SITL restarted on a new port) is a lost link, not a new peer.
void Link::follow_sender(const std::vector<Frame>& frames, const sockaddr_in& from) {
  if (locked_) return;  // only the vehicle's address gets here (handle_bytes)
  uint8_t wanted = follow_sysid_;
  for (const Frame& f : frames)
    if (wanted == 0 || f.sysid == wanted) {
      std::lock_guard lock(mutex_);
      peer_ = from;
      has_peer_ = true;
      if (wanted != 0) locked_ = true;
      return;
    }
}

}  // namespace eamos::mavlink
