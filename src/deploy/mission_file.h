#pragma once
// The mission file format, in one place: the streamed writer (mission_writer.cpp) that
// `eamos compile` and `eamos run` use, and the validating reader (mission_reader.cpp) that
// `eamos dex`, `eamos run` and the tests use. docs/architecture.md ("Mission file")
// describes the format; src/deploy/README.md says why the reader lives here.
#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "dex/mission.h"
#include "graph/pipeline.h"

namespace eamos::deploy {

/// Version of the mission file format; a DEX refuses files of another version.
/// 2: every file ends with its `file_hash`. 3: sync points are barriers over `drone_sets`
/// (`waits`, `notify`) instead of an external node and arc per peer. 4: nodes leave out
/// what the reader derives (`index`, `internal`, `clone`, `evaluated_by`, `drone` of the
/// file's own nodes) and arcs are arrays.
constexpr int kMissionFormatVersion = 4;

/// Version of the canonical form the mission hash is taken over. It changes with that
/// form, not with the files' layout: the hash names what the mission does, and the traces
/// and credentials that carry it stay the same when only the files' layout changes.
constexpr int kMissionHashFormVersion = 4;

/// The last member of every mission file: SHA-256 (hex) of every byte before it.
inline constexpr const char* kFileHashMember = "file_hash";

/// SHA-256 (hex) over the whole compiled mission: the MEG with every node's content and
/// every drone's settings and type. Two drones holding files with the same hash run the
/// same mission. One drone's file holds only its MDG, so a reader cannot recompute this
/// hash; it checks the file's own `file_hash` instead.
std::string mission_hash(const graph::Compilation& c);

/// Whether a mission text holds the members every drone's file of a compilation holds
/// alike, byte for byte: `fleet` (every drone's name) and `priorities` (one per drone).
/// A file always holds them, so a drone deployed alone has all it needs. `shared` leaves
/// them out for one process that loads the whole fleet (read_compiled_missions): with
/// them, k drones' texts would hold k² names.
enum class FleetMembers { written, shared };

/// Writes the mission file of one drone to `out`, node by node, without building the
/// document in memory: its settings and capabilities, the fleet's drone names, its MDG
/// with every internal node and the external nodes it links to, and the file hash.
/// Returns false when the stream failed.
bool write_drone_mission(std::ostream& out, const graph::Compilation& c, int drone, const std::string& hash,
                         FleetMembers fleet_members = FleetMembers::written);

/// write_drone_mission into a string: the tests hand it to read_mission.
std::string mission_text(const graph::Compilation& c, int drone, const std::string& hash,
                         FleetMembers fleet_members = FleetMembers::written);

/// write_drone_mission appended to `text`: one buffer that a caller writing many files
/// reuses, so each is made in memory already allocated, hashed there and written whole.
void append_drone_mission(std::string& text, const graph::Compilation& c, int drone, const std::string& hash,
                          FleetMembers fleet_members = FleetMembers::written);

/// The most defects one read reports; a badly damaged file would otherwise print one
/// line per node.
inline constexpr std::size_t kMaxMissionDefects = 50;

/// Reads and checks a mission file's text: its file hash, then every member, index,
/// enum, count, number range and nesting depth. True with `out` filled when the file is
/// a valid mission of this format version; false with every defect found (up to
/// kMaxMissionDefects) as "FILE: error: WHERE: WHAT", WHERE a JSON pointer into the file.
/// `file` names the file in the messages.
bool read_mission(std::string_view text, const std::string& file, dex::Mission& out,
                  std::vector<std::string>& errors);

/// Bytes a mission file may hold: `eamos compile` writes about 0.2 MB a drone for 500,000
/// nodes over 1,000 drones; a larger file is refused unread.
constexpr std::uint64_t kMaxMissionFileBytes = std::uint64_t{1} << 30;

/// The tables the missions of one process hold in common, filled by the reads that share
/// them: the fleet's names and their index, the priorities, and each drone set by its
/// `[first, last]` ranges (a fleet-wide set is one range), expanded once. A read given
/// filled tables takes `fleet` and `priorities` from them when its text leaves them out
/// (FleetMembers::shared), so each drone's read costs what its own part holds.
struct FleetTables {
  dex::SharedTable<std::vector<std::string>> fleet;
  std::unordered_map<std::string, int> index;  ///< drone name → its place in `fleet`
  dex::SharedTable<std::vector<int>> priorities;
  std::map<std::vector<std::pair<int, int>>, dex::SharedTable<std::vector<int>>> sets;
};

/// read_mission with `tables` shared by every read of one process: see FleetTables.
bool read_mission(std::string_view text, const std::string& file, dex::Mission& out,
                  std::vector<std::string>& errors, FleetTables& tables);

/// Every drone's mission of `c`, checked by read_mission as its DEX checks its file, for
/// the tests that compare it with compiled_missions, which builds the same without the
/// texts. The first drone's text is its whole
/// file; the others' leave the fleet-wide members to the tables their reads share, so
/// loading k drones costs and holds what their own parts hold, not k² names. False with
/// every defect in `errors`. `text_bytes`, when given, receives the bytes of text read.
bool read_compiled_missions(const graph::Compilation& c, std::vector<dex::Mission>& out,
                            std::vector<std::string>& errors, std::size_t* text_bytes = nullptr);

/// Every drone's mission of `c` built from its MDG in memory, for a process that compiled
/// the mission itself (`eamos run`, `eamos verify`, the Python module): the structure read_compiled_missions
/// reads from the texts, without writing, hashing and parsing them (the shared tables too).
/// Each carries mission_hash(c), as the files do. False, with what is wrong in `errors`,
/// only for a compiled mission the file's reader would refuse too.
bool compiled_missions(const graph::Compilation& c, std::vector<dex::Mission>& out,
                       std::vector<std::string>& errors);

/// read_mission of the file at `path`; a file that cannot be read, is not a regular file (a
/// FIFO, /dev/zero) or holds more than kMaxMissionFileBytes is one more defect.
bool read_mission_file(const std::string& path, dex::Mission& out, std::vector<std::string>& errors);

}  // namespace eamos::deploy
