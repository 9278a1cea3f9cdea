// The mission file and the mission hash, written as a stream: node by node from the
// compiled graphs to the file (or the digest), never as a document in memory, in an order
// a reader can use: format and version first, the file hash last. mission_reader.cpp is
// the one reader of what is written here.
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>

#include "deploy/json_writer.h"
#include "deploy/sha256.h"
#include "deploy/mission_file.h"
#include "graph/export.h"
#include "version.h"

namespace eamos::deploy {

namespace {

using graph::Compilation;
using graph::MegKind;
using graph::MegNode;

/// Mission files put each top-level member, each setting, and each node and arc on a line
/// of its own (members nested deeper stay on their parent's line).
constexpr int kMissionFileWrap = 2;

void write_vec3(JsonWriter& w, const fleet::Vec3& v) {
  w.begin_array();
  w.value(v.x);
  w.value(v.y);
  w.value(v.z);
  w.end_array();
}

void write_limits(JsonWriter& w, const fleet::Limits& l) {
  w.begin_object();
  w.member("max_speed", l.max_speed_mps);
  w.member("max_climb", l.max_climb_mps);
  w.member("max_descent", l.max_descent_mps);
  w.member("max_accel", l.max_accel_mps2);
  w.member("max_altitude", l.max_altitude_m);
  w.end_object();
}

void write_tolerance(JsonWriter& w, const fleet::GoalTolerance& t) {
  w.begin_object();
  w.member("horizontal", t.horizontal_m);
  w.member("vertical", t.vertical_m);
  w.member("speed", t.settled_mps);
  w.end_object();
}

void write_optional(JsonWriter& w, const char* key, const std::optional<double>& v) {
  if (v) w.member(key, *v);
}

// Written only when the fleet sets a rule, so a mission without `safety:` keeps its bytes.
void write_site(JsonWriter& w, const fleet::SiteLimits& site) {
  w.begin_object();
  if (site.geofence) {
    const fleet::Geofence& g = *site.geofence;
    w.key("geofence");
    w.begin_object();
    w.key("polygon");
    w.begin_array();
    for (const auto& [x, y] : g.polygon) {
      w.begin_array();
      w.value(x);
      w.value(y);
      w.end_array();
    }
    w.end_array();
    write_optional(w, "min_altitude", g.min_altitude_m);
    write_optional(w, "max_altitude", g.max_altitude_m);
    if (g.upload) w.member("upload", true);
    w.end_object();
  }
  write_optional(w, "max_speed", site.max_speed_mps);
  write_optional(w, "max_climb", site.max_climb_mps);
  write_optional(w, "max_descent", site.max_descent_mps);
  w.end_object();
}

void write_gust(JsonWriter& w, const fleet::Gust& g) {
  w.begin_object();
  w.member("at", g.at_s);
  w.member("for", g.for_s);
  w.key("velocity");
  write_vec3(w, g.velocity);
  w.end_object();
}

void write_settings(JsonWriter& w, const fleet::DroneSettings& s, int index) {
  w.begin_object();
  w.member("name", s.name);
  w.member("index", index);
  w.member("type", s.type);
  w.member("adapter", s.adapter);
  if (!s.connection.empty()) w.member("connection", s.connection);
  if (s.sysid > 0) w.member("sysid", s.sysid);
  if (s.announce_as_gcs) w.member("announce_as_gcs", true);
  // Only when the fleet sets it: mission files of fleets that do not stay byte for byte.
  if (s.home_tolerance_m != fleet::kDefaultHomeToleranceM) w.member("home_tolerance", s.home_tolerance_m);
  if (!s.signing_key.empty()) {  // the drone's own folder only, beside its private DDS key
    w.member("signing_key", s.signing_key);
    w.member("signing_setup", s.signing_setup);
  }
  w.key("home");
  write_vec3(w, s.home);
  w.member("battery", s.battery_percent);
  w.member("failsafe", fleet::failsafe_name(s.failsafe));
  w.key("limits");
  write_limits(w, s.limits);
  w.key("tolerance");
  write_tolerance(w, s.tolerance);
  if (!s.site.empty()) {
    w.key("site");
    write_site(w, s.site);
  }
  if (s.gust) {
    w.key("gust");
    write_gust(w, *s.gust);
  }
  w.key("sensors");
  w.begin_object();
  for (const auto& [name, model] : s.sensors) {
    w.key(name);
    w.begin_object();
    w.member("value", model.base);
    w.key("gradient");
    write_vec3(w, model.gradient);
    w.end_object();
  }
  w.end_object();
  w.key("timeouts");
  w.begin_object();
  for (const auto& [action, seconds] : s.timeouts_s) w.member(action, seconds);
  w.end_object();
  w.end_object();
}

/// `separation` (min_separation, when not the default) and `priorities` (when any drone
/// sets `priority:`): written only then, so a mission without them keeps its file and hash.
void write_separation(JsonWriter& w, const Compilation& c, FleetMembers fleet_members = FleetMembers::written) {
  const fleet::Separation& s = c.fleet.safety.min_separation;
  if (s.horizontal_m != fleet::Separation{}.horizontal_m || s.vertical_m != fleet::Separation{}.vertical_m) {
    w.key("separation");
    w.begin_object();
    w.member("horizontal", s.horizontal_m);
    w.member("vertical", s.vertical_m);
    w.end_object();
  }
  if (fleet_members == FleetMembers::shared) return;
  bool any = false;
  for (const fleet::DroneSettings& d : c.settings) any |= d.priority > 0;
  if (!any) return;
  w.key("priorities");
  w.begin_array();
  for (std::size_t d = 0; d < c.settings.size(); ++d)
    w.value(c.settings[d].priority > 0 ? c.settings[d].priority : static_cast<int>(d) + 1);
  w.end_array();
}

void write_type(JsonWriter& w, const fleet::DroneType& t) {
  w.begin_object();
  w.member("name", t.name);
  w.member("adapter", t.adapter);
  w.member("sensors", t.sensors);
  w.key("actions");
  w.begin_array();
  for (const auto& a : t.actions) {
    w.begin_object();
    w.member("name", a.name);
    w.key("arities");
    w.begin_array();
    for (int n : a.arities) w.value(n);
    w.end_array();
    w.member("class", fleet::action_class_name(a.action_class));
    w.end_object();
  }
  w.end_array();
  w.key("properties");
  w.begin_array();
  for (const auto& p : t.properties) {
    w.begin_object();
    w.member("name", p.name);
    w.member("type", p.type == fleet::ValueType::boolean ? "boolean" : "number");
    w.end_object();
  }
  w.end_array();
  w.end_object();
}

/// graph::expr_json as a stream.
void write_expr(JsonWriter& w, const lang::Expr& e) {
  w.begin_object();
  switch (e.kind) {
    case lang::ExprKind::number: w.member("num", e.number); break;
    case lang::ExprKind::boolean: w.member("bool", e.boolean); break;
    case lang::ExprKind::property:
      w.member("prop", e.property);
      w.member("drone", e.drone);
      break;
    case lang::ExprKind::name: w.member("name", e.drone); break;
    case lang::ExprKind::unary:
    case lang::ExprKind::binary:
      w.member("op", lang::op_text(e.op));
      w.key("args");
      w.begin_array();
      write_expr(w, *e.lhs);
      if (e.kind == lang::ExprKind::binary) write_expr(w, *e.rhs);
      w.end_array();
      break;
  }
  w.end_object();
}

void write_ints(JsonWriter& w, std::span<const int> values) {
  w.begin_array();
  for (int v : values) w.value(v);
  w.end_array();
}

void write_drone_names(JsonWriter& w, const Compilation& c, const std::vector<int>& drones) {
  w.begin_array();
  for (int d : drones) w.value(c.drone_name(d));
  w.end_array();
}

/// The members of a MEG node that every copy of it shares, in the MEG and in each MDG:
/// what it is, where it came from, and what executing it needs. `labels`: also the
/// human-readable `text` of actions and conditions, which follows from the rest (the
/// mission hash leaves it out).
/// `label`: a string the caller reuses for every node's text, so that labelling a node
/// allocates nothing.
void write_node_content(JsonWriter& w, const Compilation& c, const MegNode& n, bool labels, std::string& label) {
  w.member("kind", graph::meg_kind_name(n.kind));
  w.member("name", n.name);
  w.member("line", n.loc.line);
  w.member("col", n.loc.col);
  if (n.kind == MegKind::action) {
    w.key("args");
    w.begin_array();
    for (const lang::Expr* a : n.args) write_expr(w, *a);
    w.end_array();
    if (labels) {
      label.clear();
      graph::append_meg_node_label(label, c, n);
      w.member("text", label);
    }
  }
  if (n.kind == MegKind::condition) {
    w.member("control", lang::control_name(n.control));
    w.key("condition");
    write_expr(w, *n.condition);
    if (labels) {
      label.clear();
      lang::append_expr_text(label, *n.condition);
      w.member("text", label);
    }
    if (n.control == lang::ControlKind::RepeatFor) w.member("count", n.count);
  }
  if (!n.reads.empty()) {
    w.key("reads");
    write_drone_names(w, c, n.reads);
  }
  if (n.kind == MegKind::terminal && n.role != graph::Role::none)
    w.member("role", graph::role_name(n.role));
  if (n.kind == MegKind::pause) w.member("seconds", n.seconds);
  if (n.scope >= 0) w.member("scope", n.scope);
}

/// A sorted drone set as [first, last] ranges: a fleet-wide set is one pair.
void write_drone_ranges(JsonWriter& w, const std::vector<int>& set) {
  w.begin_array();
  for (auto [first, last] : graph::drone_ranges(set)) {
    w.begin_array();
    w.value(first);
    w.value(last);
    w.end_array();
  }
  w.end_array();
}

/// A drone's nodes lie far apart in the MEG (a fleet-wide show holds one in a thousand of
/// them), and so do their arguments: asking for them a few nodes ahead lets the writer
/// find them in the cache instead of waiting for each in turn.
void prefetch_ahead(const Compilation& c, const graph::Mdg& g, std::size_t i) {
  constexpr std::size_t kNodeAhead = 8, kArgsAhead = 4;
  if (i + kNodeAhead < g.nodes.size()) __builtin_prefetch(&c.meg.nodes[g.nodes[i + kNodeAhead].meg]);
  if (i + kArgsAhead < g.nodes.size())
    for (const lang::Expr* a : c.meg.nodes[g.nodes[i + kArgsAhead].meg].args) __builtin_prefetch(a);
}

/// The drone's MDG, node by node: graph::mdg_json's nodes and arcs without what the
/// reader derives (a node's place, whether it is internal, a condition's evaluator, an
/// arc's ends being external), each arc as an array. The drone's own nodes leave `drone`
/// out; a node that names one is another drone's.
void write_mdg(JsonWriter& w, const Compilation& c, const graph::Mdg& g) {
  w.key("drone_sets");
  w.begin_array();
  for (const std::vector<int>& set : g.drone_sets) write_drone_ranges(w, set);
  w.end_array();

  // A terminal names its condition by index in this MDG. Conditions are never cloned, so
  // their MEG id finds them.
  // A sorted array, not a hash map: one allocation per drone instead of one per condition.
  std::vector<std::pair<int, int>> condition_index;  // (MEG id, index in this MDG)
  for (std::size_t i = 0; i < g.nodes.size(); ++i)
    if (c.meg.nodes[g.nodes[i].meg].kind == MegKind::condition)
      condition_index.emplace_back(g.nodes[i].meg, static_cast<int>(i));
  std::sort(condition_index.begin(), condition_index.end());

  w.key("nodes");
  w.begin_array();
  std::string label;
  for (std::size_t i = 0; i < g.nodes.size(); ++i) {
    prefetch_ahead(c, g, i);
    const graph::MdgNode& mn = g.nodes[i];
    const MegNode& n = c.meg.nodes[mn.meg];
    w.begin_object();
    w.member("meg", mn.meg);
    if (!mn.internal) w.member("drone", c.drone_name(mn.drone));
    if (mn.waits >= 0) w.member("waits", mn.waits);
    if (mn.notify >= 0) w.member("notify", mn.notify);
    write_node_content(w, c, n, true, label);
    if (std::span<const int> cancels = g.cancels(static_cast<int>(i)); !cancels.empty()) {
      w.key("cancels");
      write_ints(w, cancels);
    }
    if (n.kind == MegKind::terminal && n.owner_condition >= 0) {
      auto it = std::lower_bound(condition_index.begin(), condition_index.end(), std::pair{n.owner_condition, -1});
      if (it != condition_index.end() && it->first == n.owner_condition) w.member("condition", it->second);
    }
    w.end_object();
  }
  w.end_array();

  w.key("arcs");
  w.begin_array();
  for (const graph::MdgArc& a : g.arcs) {  // [from, to, kind] or [from, to, kind, branch]
    w.begin_array();
    w.value(a.from);
    w.value(a.to);
    w.value(graph::arc_kind_name(a.kind));
    if (a.branch != graph::Branch::any) w.value(graph::branch_name(a.branch));
    w.end_array();
  }
  w.end_array();
}

/// The mission hash's canonical form, handed to the digest in large pieces: integers as
/// variable-length bytes (LEB128 of the zigzag form: most are one or two bytes), doubles as
/// their 8 bytes, strings and lists with their length first, so that two different missions
/// never give the same bytes and a host's byte order changes nothing.
class HashFeed {
 public:
  explicit HashFeed(Sha256& digest) : digest_(digest) {}
  ~HashFeed() { flush(); }
  HashFeed(const HashFeed&) = delete;
  HashFeed& operator=(const HashFeed&) = delete;

  void integer(long long v) {
    auto u = (static_cast<std::uint64_t>(v) << 1) ^ static_cast<std::uint64_t>(v >> 63);
    if (room() < 10) flush();
    while (u >= 0x80) {
      buffer_[used_++] = static_cast<unsigned char>(u | 0x80);
      u >>= 7;
    }
    buffer_[used_++] = static_cast<unsigned char>(u);
  }
  void number(double v) {
    auto u = std::bit_cast<std::uint64_t>(v);
    if (room() < 8) flush();
    for (int i = 0; i < 8; ++i) buffer_[used_++] = static_cast<unsigned char>(u >> (8 * i));
  }
  void text(std::string_view s) {
    integer(static_cast<long long>(s.size()));
    if (s.size() > room()) {
      flush();
      if (s.size() > room()) return digest_.update(s.data(), s.size());
    }
    std::memcpy(buffer_.data() + used_, s.data(), s.size());
    used_ += s.size();
  }
  void integers(std::span<const int> values) {
    integer(static_cast<long long>(values.size()));
    for (int v : values) integer(v);
  }

 private:
  std::size_t room() const { return buffer_.size() - used_; }
  void flush() {
    digest_.update(buffer_.data(), used_);
    used_ = 0;
  }

  Sha256& digest_;
  std::array<unsigned char, 64 * 1024> buffer_;
  std::size_t used_ = 0;
};

/// The letter an expression kind is tagged by in the canonical form: not the enum's value,
/// which a reordering of lang::ExprKind would change.
char expr_tag(lang::ExprKind kind) {
  switch (kind) {
    case lang::ExprKind::number: return 'n';
    case lang::ExprKind::boolean: return 'b';
    case lang::ExprKind::property: return 'p';
    case lang::ExprKind::name: return 'i';
    case lang::ExprKind::unary: return 'u';
    case lang::ExprKind::binary: return 'x';
  }
  return '?';
}

void feed_expr(HashFeed& h, const lang::Expr& e) {
  h.integer(expr_tag(e.kind));
  switch (e.kind) {
    case lang::ExprKind::number: h.number(e.number); break;
    case lang::ExprKind::boolean: h.integer(e.boolean); break;
    case lang::ExprKind::property:
      h.text(e.property);
      h.text(e.drone);
      break;
    case lang::ExprKind::name: h.text(e.drone); break;
    case lang::ExprKind::unary:
    case lang::ExprKind::binary:
      h.text(lang::op_text(e.op));
      feed_expr(h, *e.lhs);
      if (e.kind == lang::ExprKind::binary) feed_expr(h, *e.rhs);
      break;
  }
}

/// A MEG node as its canonical form holds it: every member a mission file's copy of it
/// has (write_node_content) and the condition's terminals and cancelled nodes.
void feed_node(HashFeed& h, const graph::Meg& meg, const MegNode& n) {
  h.integer(n.id);
  h.integer(n.drone);
  h.text(graph::meg_kind_name(n.kind));
  h.text(n.name);
  h.integer(n.loc.line);
  h.integer(n.loc.col);
  if (n.kind == MegKind::action) {
    h.integer(static_cast<long long>(n.args.size()));
    for (const lang::Expr* a : n.args) feed_expr(h, *a);
  }
  if (n.kind == MegKind::condition) {
    h.text(lang::control_name(n.control));
    feed_expr(h, *n.condition);
    h.integer(n.count);
    h.integers(meg.terminals(n.id));
    h.integers(meg.cancels(n.id));
  }
  h.integers(n.reads);
  if (n.kind == MegKind::terminal) {
    h.text(graph::role_name(n.role));
    h.integer(n.owner_condition);
  }
  if (n.kind == MegKind::pause) h.number(n.seconds);
  h.integer(n.scope);
}

}  // namespace

// The file hash is the last member, over every byte before it (docs/architecture.md,
// "Mission file"): the reader checks it without a canonical form of its own, and any edit
// of the file, even of white space, is caught.
void append_drone_mission(std::string& text, const Compilation& c, int drone, const std::string& hash,
                          FleetMembers fleet_members) {
  std::size_t start = text.size();
  JsonWriter w(text, kMissionFileWrap);
  w.begin_object();
  w.member("format", "eamos-mission");
  w.member("format_version", kMissionFormatVersion);
  w.member("compiler", std::string("eamos ") + EAMOS_VERSION);
  w.member("mission_hash", hash);
  w.key("source");
  w.begin_object();
  w.member("path", c.source->path);
  w.member("package", c.mission.package);
  w.end_object();
  w.key("drone");
  write_settings(w, c.settings[drone], drone);
  w.key("type");
  write_type(w, c.checked.drone_types[drone]);
  if (fleet_members == FleetMembers::written) {
    w.key("fleet");
    w.begin_array();
    for (int d = 0; d < c.drone_count(); ++d) w.value(c.drone_name(d));
    w.end_array();
  }
  const graph::Mdg& g = c.mdgs[drone];
  w.key("reads");
  write_drone_names(w, c, g.reads);
  write_separation(w, c, fleet_members);
  write_mdg(w, c, g);
  w.flush();  // the text holds every byte written so far
  Sha256 sha;
  sha.update(text.data() + start, text.size() - start);
  w.member(kFileHashMember, sha.hex_digest());
  w.end_object();
}

bool write_drone_mission(std::ostream& out, const Compilation& c, int drone, const std::string& hash,
                         FleetMembers fleet_members) {
  std::string text;
  append_drone_mission(text, c, drone, hash, fleet_members);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  return static_cast<bool>(out);
}

std::string mission_text(const Compilation& c, int drone, const std::string& hash, FleetMembers fleet_members) {
  std::string text;
  append_drone_mission(text, c, drone, hash, fleet_members);
  return text;
}

// The canonical form hashed: every drone's settings and type and the separation rules as
// one line of JSON each, then every MEG node with all of its content and every arc in
// binary (HashFeed). The digest reads it as it is made, so a large mission is hashed
// without being held in memory; in binary it costs about a third of the instructions a JSON
// form of the whole MEG did (docs/performance.md).
std::string mission_hash(const Compilation& c) {
  Sha256 sha;
  {
    HashFeed h(sha);
    h.text("eamos-mission");
    h.integer(kMissionHashFormVersion);
    std::string json;
    auto feed_json = [&](auto write) {
      json.clear();
      {
        JsonWriter w(json);
        write(w);
      }
      h.text(json);
    };
    h.integer(c.drone_count());
    for (int d = 0; d < c.drone_count(); ++d) {
      feed_json([&](JsonWriter& w) { write_settings(w, c.settings[d], d); });
      feed_json([&](JsonWriter& w) { write_type(w, c.checked.drone_types[d]); });
    }
    feed_json([&](JsonWriter& w) {
      w.begin_object();
      write_separation(w, c);
      w.end_object();
    });
    h.integer(c.meg.init);
    h.integer(c.meg.end);
    h.integer(static_cast<long long>(c.meg.nodes.size()));
    for (const MegNode& n : c.meg.nodes) feed_node(h, c.meg, n);
    h.integer(static_cast<long long>(c.meg.arcs.size()));
    for (const graph::MegArc& a : c.meg.arcs) {
      h.integer(a.from);
      h.integer(a.to);
      h.text(graph::arc_kind_name(a.kind));
      h.text(graph::branch_name(a.branch));
    }
  }  // the feed hands its last bytes to the digest here
  return sha.hex_digest();
}

}  // namespace eamos::deploy
