#pragma once
// The glibc malloc tunables the processes that hold a whole fleet or a large compile start
// with (`run` in one process, `verify`, a compile of a source of 1 MiB or more). glibc reads
// GLIBC_TUNABLES only as a program starts, so `eamos` puts them in the environment of the
// program it becomes (docs/performance.md, "Huge pages").
#include <optional>
#include <string>
#include <string_view>

namespace eamos::cli {

/// Transparent huge pages for the heap (where the kernel offers them on request, as Debian's
/// `madvise` setting does): for a heap of hundreds of MB touched a page at a time, a tenth of
/// the page faults and less CPU besides. Blocks under 32 MiB come from that heap too rather
/// than from mappings of their own on 4 KiB pages (glibc's threshold starts at 128 KiB): a
/// third fewer page faults for the 500,000-statement compiles. And the heap keeps what is
/// freed (trimmed only past 4 GiB free): verify's threads fly path after path, and each arena
/// handed its pages back after every flight only to fault them in again (216,000 page faults
/// for the 100-drone squads' 64 paths, 8,500 without).
inline constexpr std::string_view kHeapTunables =
    "glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=33554432:glibc.malloc.trim_threshold=4294967296";

/// GLIBC_TUNABLES with ours in front of the user's `theirs` (a later setting wins, so theirs
/// do); nothing when theirs already choose huge pages or not.
inline std::optional<std::string> heap_tunables(std::string_view theirs) {
  if (theirs.find("glibc.malloc.hugetlb") != std::string_view::npos) return std::nullopt;
  std::string tunables(kHeapTunables);
  if (!theirs.empty()) tunables.append(":").append(theirs);
  return tunables;
}

}  // namespace eamos::cli
