#include "deploy/regular_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace eamos::deploy {

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

}  // namespace

FileRead read_regular_file(const std::string& path, std::uint64_t max_bytes, std::string& text) {
  text.clear();
  Fd f{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
  struct stat st {};
  if (f.fd < 0 || ::fstat(f.fd, &st) != 0) return {FileRead::cannot_open, std::strerror(errno)};
  if (!S_ISREG(st.st_mode)) return {FileRead::not_regular, kind_of(st.st_mode)};
  if (static_cast<std::uint64_t>(st.st_size) > max_bytes) return {FileRead::too_large, std::to_string(st.st_size)};
  text.reserve(static_cast<std::size_t>(st.st_size));
  return read_all(f.fd, max_bytes, text);
}

}  // namespace eamos::deploy
