// The one reader of mission files. A mission file arrives from outside (copied to a
// companion computer, possibly edited or damaged), so nothing in it is trusted: the file
// hash is recomputed, and every member the DEX uses is checked for its type, its range,
// the index it names and the enum value it spells, before the engine sees any of it. The
// engine indexes nodes, arcs and drones without checks; this is where they are made safe.
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <unordered_map>

#include <nlohmann/json.hpp>

#include "deploy/mission_file.h"
#include "diag/file_read.h"
#include "deploy/sha256.h"
#include "lang/parser.h"

namespace eamos::deploy {

namespace {

using nlohmann::json;

/// Expression trees as deep as the compiler accepts them; each level is an object and an
/// `args` array in the file, plus the members around the expression.
constexpr int kMaxExpressionDepth = lang::Parser::kMaxExpressionDepth + 8;
constexpr int kMaxJsonDepth = 2 * kMaxExpressionDepth + 16;
constexpr std::size_t kMaxDrones = 100000;
constexpr std::size_t kMaxNameLength = 256;
constexpr int kMaxArity = 16;

std::string at(const std::string& where, const std::string& key) { return where + "/" + key; }
std::string at(const std::string& where, std::size_t i) { return where + "/" + std::to_string(i); }

/// Where a value is, built into a JSON pointer only when there is a defect to report:
/// a valid file of 500,000 nodes must not pay for a path string per member.
struct Loc {
  Loc(const std::string& base) : base(base) {}  // NOLINT: a path is a Loc
  Loc(const char* base) : base(base) {}         // NOLINT
  Loc(const std::string& base, const char* key) : base(base), key(key) {}
  std::string_view base;  ///< what it points at outlives the Loc (a call's argument)
  const char* key = nullptr;
  std::string str() const { return key ? std::string(base) + "/" + key : std::string(base); }
};

/// Collects defects with where they are; stops collecting at kMaxMissionDefects.
struct Defects {
  std::string file;
  std::vector<std::string>& out;
  std::size_t dropped = 0;

  void add(const Loc& loc, const std::string& what) {
    if (out.size() >= kMaxMissionDefects) {
      ++dropped;
      return;
    }
    std::string where = loc.str();
    out.push_back(file + ": error: " + (where.empty() ? "" : where + ": ") + what);
  }
  bool any() const { return !out.empty(); }
};

const char* type_name(const json& j) {
  return j.is_discarded() ? "nothing" : j.type_name();
}

/// The typed member readers: false (and a defect) when the member is missing and
/// required, of the wrong type or out of range; `out` is left as it was then. A missing
/// optional member is no defect: true, `out` unchanged.
class Fields {
 public:
  explicit Fields(Defects& d) : d_(d) {}

  const json* member(const json& obj, const char* key, const std::string& where, bool required = true) {
    auto it = obj.find(key);
    if (it == obj.end()) {
      if (required) d_.add(where, std::string("member \"") + key + "\" is missing");
      return nullptr;
    }
    return &*it;
  }

  bool object(const json& j, const Loc& where) { return expect(j.is_object(), j, "an object", where); }
  bool array(const json& j, const Loc& where) { return expect(j.is_array(), j, "an array", where); }

  bool string(const json& obj, const char* key, const std::string& where, std::string& out,
              bool required = true, std::size_t max_length = kMaxNameLength) {
    const json* j = member(obj, key, where, required);
    return j ? string_value(*j, Loc(where, key), out, max_length) : !required;
  }

  bool string_value(const json& j, const Loc& where, std::string& out,
                    std::size_t max_length = kMaxNameLength) {
    if (!expect(j.is_string(), j, "a string", where)) return false;
    const std::string& s = j.get_ref<const std::string&>();
    if (s.size() > max_length) {
      d_.add(where, "string of " + std::to_string(s.size()) + " bytes is longer than the " +
                        std::to_string(max_length) + " allowed");
      return false;
    }
    out = s;
    return true;
  }

  template <typename Int>
  bool integer(const json& obj, const char* key, const std::string& where, Int& out, long long lo,
               long long hi, bool required = true) {
    const json* j = member(obj, key, where, required);
    return j ? integer_value(*j, Loc(where, key), out, lo, hi) : !required;
  }

  template <typename Int>
  bool integer_value(const json& j, const Loc& where, Int& out, long long lo, long long hi) {
    if (!expect(j.is_number_integer(), j, "a whole number", where)) return false;
    // Non-negative whole numbers are held unsigned: compare them so, or 2^64-1 reads as -1.
    bool in_range = j.is_number_unsigned()
                        ? hi >= 0 && j.get<unsigned long long>() <= static_cast<unsigned long long>(hi) &&
                              static_cast<long long>(j.get<unsigned long long>()) >= lo
                        : j.get<long long>() >= lo && j.get<long long>() <= hi;
    if (!in_range) {
      d_.add(where, j.dump() + " is out of range (" + std::to_string(lo) + " to " + std::to_string(hi) + ")");
      return false;
    }
    out = static_cast<Int>(j.get<long long>());
    return true;
  }

  bool number(const json& obj, const char* key, const std::string& where, double& out, double lo, double hi,
              bool required = true) {
    const json* j = member(obj, key, where, required);
    return j ? number_value(*j, Loc(where, key), out, lo, hi) : !required;
  }

  bool number_value(const json& j, const Loc& where, double& out, double lo, double hi) {
    // JSON has no NaN or infinity (the writer would have written null): a finite number only.
    if (!expect(j.is_number(), j, "a number", where)) return false;
    double v = j.get<double>();
    if (!std::isfinite(v) || v < lo || v > hi) {
      d_.add(where, j.dump() + " is out of range (" + range_text(lo, hi) + ")");
      return false;
    }
    out = v;
    return true;
  }

  bool boolean(const json& obj, const char* key, const std::string& where, bool& out, bool required = true) {
    const json* j = member(obj, key, where, required);
    if (!j) return !required;
    if (!expect(j->is_boolean(), *j, "true or false", Loc(where, key))) return false;
    out = j->get<bool>();
    return true;
  }

  /// A string member that must be one of `names`; its index in `names`.
  bool one_of(const json& obj, const char* key, const std::string& where, const std::vector<std::string>& names,
              int& out, bool required = true) {
    if (!obj.contains(key) && !required) return true;
    const json* j = member(obj, key, where, required);
    return j && one_of_value(*j, Loc(where, key), names, out);
  }

  bool one_of_value(const json& j, const Loc& where, const std::vector<std::string>& names, int& out) {
    std::string s;
    if (!string_value(j, where, s)) return false;
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == s) return out = static_cast<int>(i), true;
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    d_.add(where, "unknown value \"" + s + "\" (expected one of: " + list + ")");
    return false;
  }

  Defects& defects() { return d_; }

 private:
  bool expect(bool ok, const json& j, const char* what, const Loc& where) {
    if (!ok) d_.add(where, std::string("expected ") + what + ", found " + type_name(j));
    return ok;
  }
  static std::string range_text(double lo, double hi) {
    auto text = [](double v) {
      if (v == std::numeric_limits<double>::max()) return std::string("any");
      if (v == -std::numeric_limits<double>::max()) return std::string("-any");
      std::ostringstream s;
      s << v;
      return s.str();
    };
    return "finite, " + text(lo) + " to " + text(hi);
  }

  Defects& d_;
};

constexpr double kAny = std::numeric_limits<double>::max();
/// Corners a geofence polygon may have in a mission file: far beyond any site's, small
/// enough that the in-flight checks of every target stay cheap.
constexpr std::size_t kMaxFenceCorners = 10000;

template <typename Enum>
std::vector<std::string> names_of(std::initializer_list<Enum> values, const char* (*name)(Enum)) {
  std::vector<std::string> out;
  for (Enum v : values) out.push_back(name(v));
  return out;
}

const std::vector<std::string>& meg_kinds() {
  using graph::MegKind;
  static const auto names = names_of({MegKind::init, MegKind::action, MegKind::fork, MegKind::condition,
                                      MegKind::terminal, MegKind::pause, MegKind::end},
                                     graph::meg_kind_name);
  return names;
}

const std::vector<std::string>& arc_kinds() {
  using graph::ArcKind;
  static const auto names =
      names_of({ArcKind::exec, ArcKind::back, ArcKind::partner, ArcKind::stop}, graph::arc_kind_name);
  return names;
}

const std::vector<std::string>& branches() {
  using graph::Branch;
  static const auto names =
      names_of({Branch::any, Branch::true_, Branch::false_, Branch::go, Branch::repeat, Branch::exit, Branch::do_,
                Branch::skip, Branch::done, Branch::continue_},
               graph::branch_name);
  return names;
}

const std::vector<std::string>& controls() {
  using lang::ControlKind;
  static const auto names = names_of(
      {ControlKind::none, ControlKind::If, ControlKind::WaitUntil, ControlKind::WaitWhile, ControlKind::RepeatUntil,
       ControlKind::RepeatWhile, ControlKind::RepeatFor, ControlKind::PauseUntil, ControlKind::PauseWhile,
       ControlKind::PauseFor, ControlKind::DoUntilAsync, ControlKind::DoWhileAsync, ControlKind::DoUntilSync,
       ControlKind::DoWhileSync},
      lang::control_name);
  return names;
}

const std::vector<std::string> kFailsafes = {"land", "return_home", "hover"};
const std::vector<std::string> kActionClasses = {"motion", "payload", "system"};
const std::vector<std::string> kValueTypes = {"number", "boolean"};
const std::vector<std::string> kUnaryOps = {"-", "!"};
const std::vector<std::string> kBinaryOps = {"+", "-", "*", "/", "<", "<=", ">", ">=", "==", "!=", "&&", "||"};

bool contains(const std::vector<std::string>& list, const std::string& s) {
  return std::find(list.begin(), list.end(), s) != list.end();
}

/// Reads one mission document into a dex::Mission, member by member.
class Reader {
 public:
  Reader(Defects& d, dex::Mission& m, FleetTables& tables) : f_(d), d_(d), m_(m), t_(tables) {}

  void read(const json& file) {
    if (!f_.object(file, "")) return;
    m_.self = -1;  // until the drone's name is found in the fleet
    header(file);
    if (!fleet(file)) return;  // every later check names drones of the fleet
    settings(file);
    type(file);
    drone_list(file, "reads", "", m_.reads);
    separation(file);
    drone_sets(file);
    nodes(file);
    arcs(file);
    node_references();
    if (!d_.any()) dex::link_mission(m_);  // nodes() refused a repeated (meg, drone) already
  }

 private:
  void header(const json& file) {
    std::string format;
    if (f_.string(file, "format", "", format) && format != "eamos-mission")
      d_.add("/format", "\"" + format + "\" is not an eamos mission file (expected \"eamos-mission\")");
    int version = 0;
    if (f_.integer(file, "format_version", "", version, 0, std::numeric_limits<int>::max()) &&
        version != kMissionFormatVersion)
      d_.add("/format_version", "format version " + std::to_string(version) + " is not supported by this DEX (knows " +
                                    std::to_string(kMissionFormatVersion) + "); compile the mission with a matching eamos");
    std::string compiler;
    f_.string(file, "compiler", "", compiler);
    if (f_.string(file, "mission_hash", "", m_.hash) && !is_hex_digest(m_.hash))
      d_.add("/mission_hash", "not a SHA-256 (64 lowercase hex digits)");
    if (const json* source = f_.member(file, "source", ""); source && f_.object(*source, "/source")) {
      f_.string(*source, "path", "/source", m_.source, true, 4096);
      std::string package;
      f_.string(*source, "package", "/source", package);
    }
  }

  /// `fleet`: required, unless the tables shared with earlier reads hold it already.
  bool fleet(const json& file) {
    const json* fleet = f_.member(file, "fleet", "", t_.fleet.empty());
    if (!fleet) {
      m_.fleet = t_.fleet;
      return !t_.fleet.empty();
    }
    if (!f_.array(*fleet, "/fleet")) return false;
    if (fleet->empty() || fleet->size() > kMaxDrones) {
      d_.add("/fleet", "a fleet of " + std::to_string(fleet->size()) + " drones (expected 1 to " +
                           std::to_string(kMaxDrones) + ")");
      return false;
    }
    bool ok = true;
    std::vector<std::string> names;
    names.reserve(fleet->size());
    std::unordered_map<std::string, int> index;
    for (std::size_t i = 0; i < fleet->size(); ++i) {
      std::string name;
      if (!f_.string_value((*fleet)[i], at("/fleet", i), name)) {
        ok = false;
        continue;
      }
      if (name.empty() || index.count(name) > 0) {
        d_.add(at("/fleet", i), name.empty() ? "empty drone name" : "drone \"" + name + "\" is listed twice");
        ok = false;
      }
      index.emplace(name, static_cast<int>(names.size()));
      names.push_back(std::move(name));
    }
    fleet_in_file_ = true;
    if (ok && t_.fleet.get() == names) {  // the fleet an earlier read shares: keep its tables
      m_.fleet = t_.fleet;
      return true;
    }
    // This file's fleet is the one its later members name, and the one later reads share.
    t_ = FleetTables{};
    t_.fleet = dex::SharedTable<std::vector<std::string>>(std::move(names));
    t_.index = std::move(index);
    m_.fleet = t_.fleet;
    return ok;
  }

  /// `separation` and `priorities`: optional, the defaults when absent (mission_writer.cpp).
  void separation(const json& file) {
    if (const json* s = f_.member(file, "separation", "", false); s && f_.object(*s, "/separation")) {
      f_.number(*s, "horizontal", "/separation", m_.separation.horizontal_m, 1e-9, kAny);
      f_.number(*s, "vertical", "/separation", m_.separation.vertical_m, 1e-9, kAny);
    }
    const json* list = f_.member(file, "priorities", "", false);
    if (!list && !fleet_in_file_) m_.priorities = t_.priorities;  // the ones an earlier read took
    if (!list || !f_.array(*list, "/priorities")) return;
    if (list->size() != m_.fleet.size())
      return d_.add("/priorities", "holds " + std::to_string(list->size()) + " priorities for a fleet of " +
                                       std::to_string(m_.fleet.size()));
    std::vector<int> priorities(list->size(), 0);
    for (std::size_t i = 0; i < list->size(); ++i)
      f_.integer_value((*list)[i], at("/priorities", i), priorities[i], 1, 1000000);
    m_.priorities = t_.priorities = dex::SharedTable<std::vector<int>>(std::move(priorities));
  }

  /// `drone_sets`: each a list of [first, last] drone index ranges, ascending and apart.
  /// A set is expanded once per list of ranges (FleetTables::sets): k drones that all wait
  /// at a fleet-wide barrier hold one list of k drones, built once.
  void drone_sets(const json& file) {
    const json* list = f_.member(file, "drone_sets", "", false);
    if (!list || !f_.array(*list, "/drone_sets")) return;
    for (std::size_t i = 0; i < list->size(); ++i) {
      std::string where = at("/drone_sets", i);
      std::vector<std::pair<int, int>> ranges;
      const json& list_i = (*list)[i];
      bool ok = f_.array(list_i, where);
      for (std::size_t r = 0; ok && r < list_i.size(); ++r) ok = drone_range(list_i[r], at(where, r), ranges);
      if (!ok) {
        m_.drone_sets.emplace_back();
        continue;
      }
      auto [it, added] = t_.sets.try_emplace(std::move(ranges));
      if (added) {
        std::vector<int> set;
        for (auto [first, last] : it->first)
          for (int d = first; d <= last; ++d) set.push_back(d);
        it->second = dex::SharedTable<std::vector<int>>(std::move(set));
      }
      m_.drone_sets.push_back(it->second);
    }
  }

  bool drone_range(const json& j, const std::string& where, std::vector<std::pair<int, int>>& ranges) {
    if (!f_.array(j, where)) return false;
    if (j.size() != 2) return d_.add(where, "a drone range is [first, last]"), false;
    int last_drone = static_cast<int>(m_.fleet.size()) - 1;
    int first = 0, last = 0;
    if (!f_.integer_value(j[0], at(where, 0), first, 0, last_drone) ||
        !f_.integer_value(j[1], at(where, 1), last, first, last_drone))
      return false;
    if (!ranges.empty() && first <= ranges.back().second + 1)
      return d_.add(where, "ranges must ascend with a gap between them"), false;
    ranges.emplace_back(first, last);
    return true;
  }

  /// A sync point's `waits` (internal clones) and `notify` (its drone's arrival).
  bool barrier(const json& j, const std::string& where, dex::Node& n) {
    int last_set = static_cast<int>(m_.drone_sets.size()) - 1;
    bool ok = f_.integer(j, "waits", where, n.waits, -1, last_set, false);
    ok &= f_.integer(j, "notify", where, n.notify, -1, last_set, false);
    if (!ok) return false;
    if ((n.waits >= 0 || n.notify >= 0) && !graph::is_sync_point(n.kind))
      return d_.add(where, "only a sync point (init or fork) waits for or notifies drones"), false;
    if (n.waits >= 0 && !n.internal) return d_.add(at(where, "waits"), "an external node waits for nothing"), false;
    return true;
  }

  /// The index in the fleet of the drone named by `j`, or -1 (and a defect).
  int drone_index(const json& j, const Loc& where) {
    std::string name;
    if (!f_.string_value(j, where, name)) return -1;
    auto it = t_.index.find(name);
    if (it == t_.index.end()) {
      d_.add(where, "drone \"" + name + "\" is not in the mission's fleet");
      return -1;
    }
    return it->second;
  }

  void drone_list(const json& obj, const char* key, const std::string& where, std::vector<int>& out) {
    const json* list = f_.member(obj, key, where);
    if (!list || !f_.array(*list, Loc(where, key))) return;
    for (std::size_t i = 0; i < list->size(); ++i) {
      int d = drone_index((*list)[i], at(at(where, key), i));
      if (d >= 0) out.push_back(d);
    }
  }

  bool vec3(const json& obj, const char* key, const std::string& where, fleet::Vec3& out) {
    const json* v = f_.member(obj, key, where);
    std::string here = at(where, key);
    if (!v || !f_.array(*v, here)) return false;
    if (v->size() != 3) {
      d_.add(here, "expected 3 numbers [x, y, z], found " + std::to_string(v->size()));
      return false;
    }
    // Each coordinate is checked, so that every bad one is reported.
    bool ok = f_.number_value((*v)[0], at(here, 0), out.x, -kAny, kAny);
    ok &= f_.number_value((*v)[1], at(here, 1), out.y, -kAny, kAny);
    ok &= f_.number_value((*v)[2], at(here, 2), out.z, -kAny, kAny);
    return ok;
  }

  void settings(const json& file) {
    const json* d = f_.member(file, "drone", "");
    if (!d || !f_.object(*d, "/drone")) return;
    fleet::DroneSettings& s = m_.settings;
    if (f_.string(*d, "name", "/drone", s.name)) {
      m_.self = drone_index((*d)["name"], "/drone/name");
      int index = -1;
      if (f_.integer(*d, "index", "/drone", index, 0, static_cast<long long>(kMaxDrones)) && m_.self >= 0 &&
          index != m_.self)
        d_.add("/drone/index", "index " + std::to_string(index) + " is not the drone's place in the fleet (" +
                                   std::to_string(m_.self) + ")");
    }
    f_.string(*d, "type", "/drone", s.type);
    f_.string(*d, "adapter", "/drone", s.adapter);
    f_.string(*d, "connection", "/drone", s.connection, false, 4096);
    f_.integer(*d, "sysid", "/drone", s.sysid, 1, 255, false);
    if (f_.string(*d, "signing_key", "/drone", s.signing_key, false, 64))
      if (std::string why = fleet::signing_key_problem(s.signing_key); !why.empty() && !s.signing_key.empty())
        d_.add("/drone/signing_key", why);
    f_.boolean(*d, "signing_setup", "/drone", s.signing_setup, false);
    f_.boolean(*d, "announce_as_gcs", "/drone", s.announce_as_gcs, false);
    f_.number(*d, "home_tolerance", "/drone", s.home_tolerance_m, 1e-9, 1e6, false);
    vec3(*d, "home", "/drone", s.home);
    f_.number(*d, "battery", "/drone", s.battery_percent, 0, 100);
    int failsafe = 0;
    if (f_.one_of(*d, "failsafe", "/drone", kFailsafes, failsafe)) s.failsafe = static_cast<fleet::Failsafe>(failsafe);
    limits(*d);
    tolerance(*d);
    site(*d);
    gust(*d);
    sensors(*d);
    if (const json* t = f_.member(*d, "timeouts", "/drone"); t && f_.object(*t, "/drone/timeouts"))
      for (const auto& [action, seconds] : t->items()) {
        double v = 0;
        if (f_.number_value(seconds, at("/drone/timeouts", action), v, 1e-9, kAny)) s.timeouts_s[action] = v;
      }
  }

  void limits(const json& d) {
    const json* l = f_.member(d, "limits", "/drone");
    if (!l || !f_.object(*l, "/drone/limits")) return;
    fleet::Limits& out = m_.settings.limits;
    const std::string w = "/drone/limits";
    f_.number(*l, "max_speed", w, out.max_speed_mps, 1e-9, kAny);
    f_.number(*l, "max_climb", w, out.max_climb_mps, 1e-9, kAny);
    f_.number(*l, "max_descent", w, out.max_descent_mps, 1e-9, kAny);
    f_.number(*l, "max_accel", w, out.max_accel_mps2, 1e-9, kAny);
    f_.number(*l, "max_altitude", w, out.max_altitude_m, 1e-9, kAny);
  }

  // Optional: a mission file written before the fleet file had `tolerance:` keeps the defaults.
  void tolerance(const json& d) {
    const json* t = f_.member(d, "tolerance", "/drone", false);
    if (!t || !f_.object(*t, "/drone/tolerance")) return;
    fleet::GoalTolerance& out = m_.settings.tolerance;
    const std::string w = "/drone/tolerance";
    f_.number(*t, "horizontal", w, out.horizontal_m, 1e-9, kAny);
    f_.number(*t, "vertical", w, out.vertical_m, 1e-9, kAny);
    f_.number(*t, "speed", w, out.settled_mps, 1e-9, kAny);
  }

  // Optional: written only when the fleet file has rules for the site.
  void site(const json& d) {
    const json* j = f_.member(d, "site", "/drone", false);
    if (!j || !f_.object(*j, "/drone/site")) return;
    fleet::SiteLimits& out = m_.settings.site;
    const std::string w = "/drone/site";
    optional_number(*j, "max_speed", w, out.max_speed_mps, 1e-9);
    optional_number(*j, "max_climb", w, out.max_climb_mps, 1e-9);
    optional_number(*j, "max_descent", w, out.max_descent_mps, 1e-9);
    const json* g = f_.member(*j, "geofence", w, false);
    if (!g || !f_.object(*g, "/drone/site/geofence")) return;
    fleet::Geofence fence;
    const std::string gw = "/drone/site/geofence";
    optional_number(*g, "min_altitude", gw, fence.min_altitude_m, -kAny);
    optional_number(*g, "max_altitude", gw, fence.max_altitude_m, -kAny);
    f_.boolean(*g, "upload", gw, fence.upload, false);
    if (polygon(*g, gw, fence)) out.geofence = std::move(fence);
  }

  void optional_number(const json& obj, const char* key, const std::string& where, std::optional<double>& out,
                       double lo) {
    double v = 0;
    if (obj.contains(key) && f_.number(obj, key, where, v, lo, kAny)) out = v;
  }

  bool polygon(const json& g, const std::string& where, fleet::Geofence& out) {
    const json* p = f_.member(g, "polygon", where);
    std::string here = at(where, "polygon");
    if (!p || !f_.array(*p, here)) return false;
    if (p->size() < 3 || p->size() > kMaxFenceCorners) {
      d_.add(here, std::to_string(p->size()) + " corners; a polygon has 3 to " + std::to_string(kMaxFenceCorners));
      return false;
    }
    bool ok = true;
    for (std::size_t i = 0; i < p->size(); ++i) {
      const json& c = (*p)[i];
      std::string ci = at(here, static_cast<int>(i));
      if (!f_.array(c, ci) || c.size() != 2) {
        if (c.is_array()) d_.add(ci, "expected 2 numbers [x, y], found " + std::to_string(c.size()));
        ok = false;
        continue;
      }
      double x = 0, y = 0;
      ok &= f_.number_value(c[0], at(ci, 0), x, -kAny, kAny) & f_.number_value(c[1], at(ci, 1), y, -kAny, kAny);
      out.polygon.push_back({x, y});
    }
    return ok;
  }

  void gust(const json& d) {
    const json* j = f_.member(d, "gust", "/drone", false);
    if (!j || !f_.object(*j, "/drone/gust")) return;
    fleet::Gust g;
    bool ok = f_.number(*j, "at", "/drone/gust", g.at_s, 0, kAny);
    ok &= f_.number(*j, "for", "/drone/gust", g.for_s, 1e-9, kAny);
    ok &= vec3(*j, "velocity", "/drone/gust", g.velocity);
    if (ok) m_.settings.gust = g;
  }

  void sensors(const json& d) {
    const json* sensors = f_.member(d, "sensors", "/drone");
    if (!sensors || !f_.object(*sensors, "/drone/sensors")) return;
    for (const auto& [name, model] : sensors->items()) {
      std::string where = at("/drone/sensors", name);
      if (!f_.object(model, where)) continue;
      fleet::SensorModel s;
      bool ok = f_.number(model, "value", where, s.base, -kAny, kAny);
      ok &= vec3(model, "gradient", where, s.gradient);
      if (ok) m_.settings.sensors[name] = s;
    }
  }

  void type(const json& file) {
    const json* t = f_.member(file, "type", "");
    if (!t || !f_.object(*t, "/type")) return;
    fleet::DroneType& type = m_.type;
    type.generic = false;
    f_.string(*t, "name", "/type", type.name);
    f_.string(*t, "adapter", "/type", type.adapter);
    f_.integer(*t, "sensors", "/type", type.sensors, 0, fleet::kMaxSensors);
    if (const json* list = f_.member(*t, "actions", "/type"); list && f_.array(*list, "/type/actions"))
      for (std::size_t i = 0; i < list->size(); ++i) action_spec((*list)[i], at("/type/actions", i));
    if (const json* list = f_.member(*t, "properties", "/type"); list && f_.array(*list, "/type/properties"))
      for (std::size_t i = 0; i < list->size(); ++i) {
        const json& p = (*list)[i];
        std::string where = at("/type/properties", i);
        fleet::PropertySpec spec;
        int value_type = 0;
        if (!f_.object(p, where)) continue;
        bool ok = f_.string(p, "name", where, spec.name);
        ok &= f_.one_of(p, "type", where, kValueTypes, value_type);
        if (ok) {
          spec.type = value_type == 1 ? fleet::ValueType::boolean : fleet::ValueType::number;
          type.properties.push_back(spec);
        }
      }
  }

  void action_spec(const json& a, const std::string& where) {
    if (!f_.object(a, where)) return;
    fleet::ActionSpec spec;
    int action_class = 0;
    bool ok = f_.string(a, "name", where, spec.name);
    ok &= f_.one_of(a, "class", where, kActionClasses, action_class);
    spec.action_class = action_class == 1   ? fleet::ActionClass::payload
                        : action_class == 2 ? fleet::ActionClass::system
                                            : fleet::ActionClass::motion;
    const json* arities = f_.member(a, "arities", where);
    if (!arities || !f_.array(*arities, at(where, "arities"))) return;
    for (std::size_t i = 0; i < arities->size(); ++i) {
      int n = 0;
      if (f_.integer_value((*arities)[i], at(at(where, "arities"), i), n, 0, kMaxArity)) spec.arities.push_back(n);
      else ok = false;
    }
    if (ok) m_.type.actions.push_back(spec);
  }

  // --- expressions -------------------------------------------------------------------

  bool expr(const json& j, const std::string& where, dex::Expr& out, int depth) {
    if (depth > kMaxExpressionDepth) {
      d_.add(where, "expression nested more than " + std::to_string(kMaxExpressionDepth) + " levels deep");
      return false;
    }
    if (!f_.object(j, where)) return false;
    if (j.contains("num")) {
      out.kind = dex::Expr::Kind::number;
      return f_.number(j, "num", where, out.number, -kAny, kAny);
    }
    if (j.contains("bool")) {
      out.kind = dex::Expr::Kind::boolean;
      return f_.boolean(j, "bool", where, out.boolean);
    }
    if (j.contains("prop")) {
      out.kind = dex::Expr::Kind::property;
      if (!f_.string(j, "prop", where, out.property)) return false;
      if (out.property.empty()) return d_.add(at(where, "prop"), "empty property name"), false;
      const json* drone = f_.member(j, "drone", where);
      return drone && (out.drone = drone_index(*drone, Loc(where, "drone"))) >= 0;
    }
    if (j.contains("op")) return operation(j, where, out, depth);
    d_.add(where, "not an expression (expected a member \"num\", \"bool\", \"prop\" or \"op\")");
    return false;
  }

  bool operation(const json& j, const std::string& where, dex::Expr& out, int depth) {
    const json* args = f_.member(j, "args", where);
    if (!f_.string(j, "op", where, out.op) || !args || !f_.array(*args, Loc(where, "args"))) return false;
    std::size_t n = args->size();
    bool known = n == 1 ? contains(kUnaryOps, out.op) : n == 2 && contains(kBinaryOps, out.op);
    if (!known) {
      d_.add(at(where, "op"), "no operator \"" + out.op + "\" takes " + std::to_string(n) + " operands");
      return false;
    }
    out.kind = n == 1 ? dex::Expr::Kind::unary : dex::Expr::Kind::binary;
    out.args.resize(n);
    bool ok = true;
    for (std::size_t i = 0; i < n; ++i) ok &= expr((*args)[i], at(at(where, "args"), i), out.args[i], depth + 1);
    return ok;
  }

  // --- nodes and arcs -------------------------------------------------------------------

  void nodes(const json& file) {
    const json* list = f_.member(file, "nodes", "");
    if (!list || !f_.array(*list, "/nodes")) return;
    if (list->size() > static_cast<std::size_t>(std::numeric_limits<int>::max() / 2)) {
      d_.add("/nodes", "too many nodes");
      return;
    }
    m_.nodes.resize(list->size());
    for (std::size_t i = 0; i < list->size(); ++i) {
      std::string where = at("/nodes", i);
      dex::Node& n = m_.nodes[i];
      if (!f_.object((*list)[i], where) || !node((*list)[i], where, n)) continue;
      if (!m_.index.emplace(dex::Mission::key(n.meg, n.drone), static_cast<int>(i)).second)
        d_.add(where, "a second node with MEG id " + std::to_string(n.meg) + " held by " + m_.fleet[n.drone]);
    }
  }

  bool node(const json& j, const std::string& where, dex::Node& n) {
    bool ok = f_.integer(j, "meg", where, n.meg, 0, std::numeric_limits<int>::max());
    ok &= holder(j, where, n);
    int kind = 0;
    ok &= f_.one_of(j, "kind", where, meg_kinds(), kind);
    n.kind = static_cast<graph::MegKind>(kind);
    ok &= f_.string(j, "name", where, n.name);
    n.text = n.name;
    f_.string(j, "text", where, n.text, false, 1 << 20);
    ok &= f_.integer(j, "line", where, n.line, 0, std::numeric_limits<int>::max());
    ok &= f_.integer(j, "col", where, n.col, 0, std::numeric_limits<int>::max());
    ok &= f_.integer(j, "scope", where, n.scope, -1, std::numeric_limits<int>::max(), false);
    if (!ok || !barrier(j, where, n)) return false;
    return node_content(j, where, n);
  }

  /// `drone` names the holder of another drone's node (an external one); the drone's own
  /// nodes leave it out.
  bool holder(const json& j, const std::string& where, dex::Node& n) {
    const json* drone = f_.member(j, "drone", where, false);
    n.internal = drone == nullptr;
    if (n.internal) return (n.drone = m_.self) >= 0;
    n.drone = drone_index(*drone, Loc(where, "drone"));
    if (n.drone < 0) return false;
    if (n.drone != m_.self) return true;
    d_.add(at(where, "drone"), "names this file's own drone, whose nodes leave \"drone\" out");
    return false;
  }

  bool node_content(const json& j, const std::string& where, dex::Node& n) {
    switch (n.kind) {
      case graph::MegKind::action: return action(j, where, n);
      case graph::MegKind::condition: return condition(j, where, n);
      case graph::MegKind::pause: return f_.number(j, "seconds", where, n.seconds, 0, kAny);
      default: return true;
    }
  }

  bool action(const json& j, const std::string& where, dex::Node& n) {
    const json* args = f_.member(j, "args", where);
    if (!args || !f_.array(*args, Loc(where, "args"))) return false;
    n.args.resize(args->size());
    bool ok = true;
    for (std::size_t i = 0; i < args->size(); ++i) ok &= expr((*args)[i], at(at(where, "args"), i), n.args[i], 1);
    if (!ok || !n.internal) return ok;
    // The drone runs its own actions: each must be one its type has, with that many arguments.
    for (const fleet::ActionSpec& a : m_.type.actions)
      if (a.name == n.name) {
        if (std::find(a.arities.begin(), a.arities.end(), static_cast<int>(n.args.size())) != a.arities.end())
          return true;
        d_.add(at(where, "args"), n.name + " with " + std::to_string(n.args.size()) +
                                      " arguments, which the drone's type does not take");
        return false;
      }
    d_.add(at(where, "name"), "action \"" + n.name + "\" is not one of the drone type's actions");
    return false;
  }

  bool condition(const json& j, const std::string& where, dex::Node& n) {
    int control = 0;
    bool ok = f_.one_of(j, "control", where, controls(), control);
    n.control = static_cast<lang::ControlKind>(control);
    if (ok && n.control == lang::ControlKind::none)
      ok = false, d_.add(at(where, "control"), "a condition without a control structure");
    const json* c = f_.member(j, "condition", where);
    if (!c || !expr(*c, at(where, "condition"), n.condition, 1)) ok = false;
    if (n.control == lang::ControlKind::RepeatFor)
      ok &= f_.integer(j, "count", where, n.count, 0, std::numeric_limits<long long>::max());
    if (const json* cancels = f_.member(j, "cancels", where, false);
        cancels && f_.array(*cancels, Loc(where, "cancels")))
      for (std::size_t i = 0; i < cancels->size(); ++i) {
        int c = 0;
        if (node_index((*cancels)[i], at(at(where, "cancels"), i), c)) n.cancels.push_back(c);
        else ok = false;
      }
    return ok;
  }

  bool node_index(const json& j, const Loc& where, int& out) {
    if (m_.nodes.empty()) return d_.add(where, "names a node, and the file has none"), false;
    return f_.integer_value(j, where, out, 0, static_cast<long long>(m_.nodes.size()) - 1);
  }

  void arcs(const json& file) {
    const json* list = f_.member(file, "arcs", "");
    if (!list || !f_.array(*list, "/arcs")) return;
    for (std::size_t i = 0; i < list->size(); ++i) {
      const json& j = (*list)[i];
      std::string where = at("/arcs", i);
      dex::Arc a;
      int kind = 0, branch = 0;
      if (!f_.array(j, where)) continue;
      if (j.size() != 3 && j.size() != 4) {
        d_.add(where, "an arc is [from, to, kind] or [from, to, kind, branch]");
        continue;
      }
      bool ok = node_index(j[0], at(where, 0), a.from);
      ok &= node_index(j[1], at(where, 1), a.to);
      ok &= f_.one_of_value(j[2], at(where, 2), arc_kinds(), kind);
      if (j.size() == 4) ok &= f_.one_of_value(j[3], at(where, 3), branches(), branch);
      if (!ok) continue;
      a.kind = static_cast<graph::ArcKind>(kind);
      a.branch = static_cast<graph::Branch>(branch);
      m_.arcs.push_back(a);
    }
  }

  /// Checks that need every node read: a Do condition cancels only nodes this drone runs.
  void node_references() {
    for (std::size_t i = 0; i < m_.nodes.size(); ++i)
      for (std::size_t k = 0; k < m_.nodes[i].cancels.size(); ++k)
        if (!m_.nodes[m_.nodes[i].cancels[k]].internal)
          d_.add(at(at(at("/nodes", i), "cancels"), k), "cancels node " + std::to_string(m_.nodes[i].cancels[k]) +
                                                           ", which another drone runs");
  }

  static bool is_hex_digest(const std::string& s) {
    return s.size() == 64 && s.find_first_not_of("0123456789abcdef") == std::string::npos;
  }

  Fields f_;
  Defects& d_;
  dex::Mission& m_;
  FleetTables& t_;  ///< the fleet's names, priorities and drone sets (one file's, or shared)
  bool fleet_in_file_ = false;  ///< then its priorities are the file's own too (none when absent)
};

/// Where the file hash member starts (at its comma) and its value, or npos when the file
/// does not end with it.
std::size_t file_hash_member(std::string_view text, std::string& hash) {
  std::size_t end = text.find_last_not_of(" \t\r\n");
  if (end == std::string_view::npos || text[end] != '}') return std::string_view::npos;
  std::string key = std::string("\"") + kFileHashMember + "\":\"";
  std::size_t value_end = text.find_last_not_of(" \t\r\n", end - 1);
  if (value_end == std::string_view::npos || value_end < 64 + key.size() || text[value_end] != '"')
    return std::string_view::npos;
  std::size_t key_at = value_end - 64 - key.size();
  if (text.substr(key_at, key.size()) != key) return std::string_view::npos;
  hash = std::string(text.substr(key_at + key.size(), 64));
  std::size_t comma = text.find_last_not_of(" \t\r\n", key_at - 1);
  if (comma == std::string_view::npos || text[comma] != ',') return std::string_view::npos;
  return comma;
}

void check_file_hash(std::string_view text, Defects& d) {
  std::string stored;
  std::size_t covered = file_hash_member(text, stored);
  if (covered == std::string_view::npos) {
    d.add("", std::string("the file does not end with its \"") + kFileHashMember +
                  "\"; it was not written by this eamos (compile the mission again)");
    return;
  }
  Sha256 sha;
  sha.update(text.data(), covered);
  if (sha.hex_digest() != stored)
    d.add(std::string("/") + kFileHashMember,
          "the file's content does not match its hash; it was edited or damaged after `eamos compile` "
          "(compile the mission again)");
}

/// True when brackets outside strings nest deeper than `limit`. A scan of the text before
/// parsing: cheaper than a parser callback on every value, and the DEX reads expressions
/// recursively, so depth is bounded before anything is built.
bool nests_deeper_than(std::string_view text, int limit) {
  int depth = 0;
  const char* p = text.data();
  const char* end = p + text.size();
  while (p < end) {
    char c = *p++;
    if (c == '"') {
      // Skip the string: to its closing quote, stepping over escapes.
      while (p < end && *p != '"') p += *p == '\\' ? 2 : 1;
      ++p;
    } else if (c == '[' || c == '{') {
      if (++depth > limit) return true;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return false;
}

/// Parses JSON no deeper than kMaxJsonDepth; discarded (and a defect) otherwise.
json parse_bounded(std::string_view text, Defects& d) {
  if (nests_deeper_than(text, kMaxJsonDepth)) {
    d.add("", "nested more than " + std::to_string(kMaxJsonDepth) + " levels deep");
    return json(json::value_t::discarded);
  }
  try {
    return json::parse(text.begin(), text.end());
  } catch (const json::parse_error& e) {
    d.add("", "not valid JSON (at byte " + std::to_string(e.byte) + ")");
  } catch (const json::exception&) {
    d.add("", "not valid JSON: a number too large for a double");  // e.g. 1e400 (out_of_range.406)
  }
  return json(json::value_t::discarded);
}

}  // namespace

bool read_mission(std::string_view text, const std::string& file, dex::Mission& out,
                  std::vector<std::string>& errors, FleetTables& tables) {
  std::size_t before = errors.size();
  std::vector<std::string> found;
  Defects d{file, found};
  out = dex::Mission{};
  check_file_hash(text, d);
  json doc = parse_bounded(text, d);
  if (!doc.is_discarded()) Reader(d, out, tables).read(doc);
  if (d.dropped > 0)
    found.push_back(file + ": error: " + std::to_string(d.dropped) + " more defects not shown");
  errors.insert(errors.end(), found.begin(), found.end());
  if (errors.size() == before) return true;
  out = dex::Mission{};
  return false;
}

bool read_mission(std::string_view text, const std::string& file, dex::Mission& out,
                  std::vector<std::string>& errors) {
  FleetTables own;  // a file alone holds its whole fleet
  return read_mission(text, file, out, errors, own);
}

bool read_compiled_missions(const graph::Compilation& c, std::vector<dex::Mission>& out,
                            std::vector<std::string>& errors, std::size_t* text_bytes) {
  const std::string hash = mission_hash(c);
  out.assign(c.drone_count(), dex::Mission{});
  FleetTables tables;
  std::size_t bytes = 0;
  for (int d = 0; d < c.drone_count(); ++d) {
    std::string text = mission_text(c, d, hash, d == 0 ? FleetMembers::written : FleetMembers::shared);
    bytes += text.size();
    if (!read_mission(text, c.drone_name(d) + "/mission.json", out[d], errors, tables)) return false;
  }
  if (text_bytes) *text_bytes = bytes;
  return true;
}

bool read_mission_file(const std::string& path, dex::Mission& out, std::vector<std::string>& errors) {
  std::string text;
  diag::FileRead r = diag::read_bounded_file(path, kMaxMissionFileBytes, text);
  if (r.status == diag::FileRead::ok) return read_mission(text, path, out, errors);
  std::string what;
  switch (r.status) {
    case diag::FileRead::not_regular:
      what = r.detail + ", not a regular file; a mission file is the mission.json `eamos compile` writes";
      break;
    case diag::FileRead::too_large:
      what = r.detail + " bytes, more than the " + std::to_string(kMaxMissionFileBytes) +
             " (1 GiB) a mission file may hold; split the mission";
      break;
    default:
      what = "cannot read the mission file (" + r.detail + "); check that the deployment folder holds it";
  }
  errors.push_back(path + ": error: " + what);
  return false;
}

}  // namespace eamos::deploy
