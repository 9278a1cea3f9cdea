#include "diag/file_read.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace eamos::diag {

namespace {

const char* kind_of(mode_t mode) {
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISDIR(mode)) return "a directory";
  return "not a file";
}

/// Closes the descriptor on every way out.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

/// Reads `fd` to its end, at most `max_bytes` + 1 bytes: a file that grew meanwhile shows.
FileRead read_all(int fd, std::uint64_t max_bytes, std::string& text) {
  char buf[1 << 16];
  for (;;) {
    ssize_t n = ::read(fd, buf, sizeof buf);
    if (n == 0) return {};
    if (n < 0) {
      if (errno == EINTR) continue;
      return {FileRead::cannot_read, std::strerror(errno)};
    }
    text.append(buf, static_cast<std::size_t>(n));
    if (text.size() > max_bytes) return {FileRead::too_large, std::to_string(text.size())};
  }
}

// A pipe is read as its writer writes, to its end. A named FIFO may have no writer yet: a read
// would see the end at once, so the first wait is for its first bytes or for a writer that
// came and closed (POLLHUP), as every reader of a FIFO waits for one.
FileRead read_pipe(int fd, std::uint64_t max_bytes, std::string& text) {
  int flags = ::fcntl(fd, F_GETFL);
  if (flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0) return {FileRead::cannot_read, std::strerror(errno)};
  pollfd p{fd, POLLIN, 0};
  while (::poll(&p, 1, -1) < 0)
    if (errno != EINTR) return {FileRead::cannot_read, std::strerror(errno)};
  return read_all(fd, max_bytes, text);
}

}  // namespace

FileRead read_bounded_file(const std::string& path, std::uint64_t max_bytes, std::string& text, Pipes pipes) {
  text.clear();
  Fd f{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
  struct stat st {};
  if (f.fd < 0 || ::fstat(f.fd, &st) != 0) return {FileRead::cannot_open, std::strerror(errno)};
  if (S_ISFIFO(st.st_mode) && pipes == Pipes::read) return read_pipe(f.fd, max_bytes, text);
  if (!S_ISREG(st.st_mode)) return {FileRead::not_regular, kind_of(st.st_mode)};
  if (static_cast<std::uint64_t>(st.st_size) > max_bytes) return {FileRead::too_large, std::to_string(st.st_size)};
  text.reserve(static_cast<std::size_t>(st.st_size));
  return read_all(f.fd, max_bytes, text);
}

std::string why_not_readable(const std::string& path, Pipes pipes) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return std::strerror(errno);
  if (S_ISREG(st.st_mode) || (S_ISFIFO(st.st_mode) && pipes == Pipes::read)) return "";
  return describe({FileRead::not_regular, kind_of(st.st_mode)}, 0);
}

std::string describe(const FileRead& r, std::uint64_t max_bytes) {
  switch (r.status) {
    case FileRead::ok:
      return "";
    case FileRead::not_regular:
      return r.detail + ", not a regular file";
    case FileRead::too_large: {
      std::string limit = std::to_string(max_bytes) + " bytes";
      if (max_bytes % (1u << 20) == 0) limit += " (" + std::to_string(max_bytes >> 20) + " MiB)";
      return r.detail + " bytes, more than the " + limit + " it may hold";
    }
    default:
      return r.detail;
  }
}

}  // namespace eamos::diag
