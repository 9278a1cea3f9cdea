#pragma once
// Reading YAML nodes into plain values, every mismatch reported as a diagnostic at the
// node's line and column. Private to src/fleet: nothing outside this folder sees yaml-cpp.
#include <yaml-cpp/yaml.h>

#include <set>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "fleet/fleet.h"

namespace eamos::fleet {

/// yaml-cpp counts lines and columns from 0; diagnostics count from 1.
SourceLocation location_of(const YAML::Mark& mark);
/// A node as a message shows it: "'abc'", "a list", "a map" or "nothing".
std::string describe(const YAML::Node& node);

/// "a or b", "a, b or c": the choices a message offers.
std::string one_of(const std::vector<std::string>& choices);

/// Parses `text`, which must hold at most one YAML document, into `out` (null when empty).
/// Reports a stray token or a second document and returns false; syntax errors are thrown
/// as YAML::ParserException.
bool load_one_document(const std::string& text, YAML::Node& out, const SourceFile* file,
                       Diagnostics& diags);

/// Every `what` below names the value in messages, e.g. "battery of drone 'Drone1'".
struct YamlReader {
  const SourceFile* file = nullptr;
  Diagnostics& diags;

  void error(const YAML::Node& at, const std::string& message);
  /// True for a map; null (an entry left empty) is an empty map and returns false quietly.
  bool map(const YAML::Node& node, const std::string& what);
  /// The text of a map key, or "" after reporting a non-scalar or repeated key.
  std::string key(const YAML::Node& key, std::set<std::string>& seen, const std::string& where);
  /// The text of a key that must be one of `allowed`, or "" after reporting it.
  std::string field(const YAML::Node& key, const std::vector<std::string>& allowed,
                    std::set<std::string>& seen, const std::string& where);
  /// A key that names something a mission refers to, so it must be an identifier.
  std::string name(const YAML::Node& key, std::set<std::string>& seen, const std::string& where);

  bool number(const YAML::Node& node, const std::string& what, double& out);
  bool whole_number(const YAML::Node& node, const std::string& what, long long& out);
  bool text(const YAML::Node& node, const std::string& what, std::string& out);
  /// A [x, y, z] list of three numbers.
  bool vec3(const YAML::Node& node, const std::string& what, Vec3& out);
  /// Text that must be one of `choices`.
  bool choice(const YAML::Node& node, const std::string& what,
              const std::vector<std::string>& choices, std::string& out);
};

}  // namespace eamos::fleet
