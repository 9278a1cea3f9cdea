#pragma once
// Reading a whole file that comes from outside (a mission file copied to a drone), bounded:
// only a regular file, and only up to a size, so that a FIFO, a device such as /dev/zero or
// a huge file cannot make the reader wait for ever or fill the memory.
#include <cstdint>
#include <string>

namespace eamos::deploy {

struct FileRead {
  enum Status { ok, cannot_open, not_regular, too_large, cannot_read };
  Status status = ok;
  /// cannot_open, cannot_read: the system's reason; not_regular: what it is ("a FIFO",
  /// "a character device"); too_large: its size in bytes.
  std::string detail;
};

/// The whole of `path` into `text` when it is a regular file of at most `max_bytes`. The
/// checks are made on the opened file, so what is read is what was checked, and the open
/// does not block (a FIFO without a writer would wait for one).
FileRead read_regular_file(const std::string& path, std::uint64_t max_bytes, std::string& text);

}  // namespace eamos::deploy
