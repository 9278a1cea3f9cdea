#pragma once
// Reading a whole file that comes from outside (a mission, a fleet file, a mission file copied
// to a drone, a deployment's manifest), bounded: a device such as /dev/zero or a huge file
// cannot make the reader wait for ever or fill the memory.
#include <cstdint>
#include <string>

namespace eamos::diag {

struct FileRead {
  enum Status { ok, cannot_open, not_regular, too_large, cannot_read };
  Status status = ok;
  /// cannot_open, cannot_read: the system's reason; not_regular: what it is ("a FIFO",
  /// "a character device"); too_large: its size in bytes.
  std::string detail;
};

/// What may be read besides a regular file.
enum class Pipes {
  refused,  ///< only a regular file (a mission file, a manifest: always written by eamos)
  read,     ///< also a pipe or FIFO, to its end (a source given as /dev/stdin or <(...))
};

/// The whole of `path` into `text` when it is a regular file (or, with Pipes::read, a pipe)
/// of at most `max_bytes`. The checks are made on the opened file, so what is read is what
/// was checked; opening a FIFO that `pipes` refuses does not wait for a writer.
FileRead read_bounded_file(const std::string& path, std::uint64_t max_bytes, std::string& text,
                           Pipes pipes = Pipes::refused);

/// "" when `path` is what read_bounded_file reads (a regular file, or with Pipes::read a pipe),
/// else why not: what it is ("a character device, not a regular file") or the system's
/// reason. For a reader that streams a file too large to hold whole, such as a trace.
std::string why_not_readable(const std::string& path, Pipes pipes);

/// "a character device, not a regular file", "300000000 bytes, more than the 268435456 bytes
/// (256 MiB) ..." and the system's reason otherwise: the part of an error message after
/// "cannot read FILE: ".
std::string describe(const FileRead& r, std::uint64_t max_bytes);

}  // namespace eamos::diag
