// `eamos run` and `eamos verify` build each drone's mission from the compiled MDG in memory
// (deploy::compiled_missions) instead of reading the texts `eamos compile` writes: the
// engine must get the very structure the reader makes of those texts, member for member,
// for every kind of node, setting and table, or a run would fly another mission than its
// deployment.
#include <cstdio>
#include <sstream>

#include "deploy/mission_file.h"
#include "helpers.h"

namespace eamos {
namespace {

std::string num(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

std::string vec(const fleet::Vec3& v) { return "[" + num(v.x) + " " + num(v.y) + " " + num(v.z) + "]"; }

template <typename T>
std::string ints(const T& values) {
  std::string s = "[";
  for (auto v : values) s += std::to_string(v) + " ";
  return s + "]";
}

std::string optional(const std::optional<double>& v) { return v ? num(*v) : "-"; }

void describe(std::ostream& o, const dex::Expr& e) {
  o << "(" << static_cast<int>(e.kind) << " " << num(e.number) << " " << e.boolean << " " << e.drone << " "
    << e.property << " " << e.op;
  for (const dex::Expr& a : e.args) describe(o, a);
  o << ")";
}

void describe(std::ostream& o, const fleet::DroneSettings& s) {
  o << "settings " << s.name << " " << s.type << " " << vec(s.home) << " " << num(s.battery_percent) << " "
    << static_cast<int>(s.failsafe) << " " << s.adapter << " " << s.connection << " " << s.sysid << " "
    << s.priority << " " << s.signing_key << " " << s.signing_setup << " " << s.announce_as_gcs << " "
    << num(s.home_tolerance_m) << "\n limits " << num(s.limits.max_speed_mps) << " " << num(s.limits.max_climb_mps)
    << " " << num(s.limits.max_descent_mps) << " " << num(s.limits.max_accel_mps2) << " "
    << num(s.limits.max_altitude_m) << "\n tolerance " << num(s.tolerance.horizontal_m) << " "
    << num(s.tolerance.vertical_m) << " " << num(s.tolerance.settled_mps) << "\n";
  for (const auto& [name, model] : s.sensors) o << " sensor " << name << " " << num(model.base) << " " << vec(model.gradient) << "\n";
  for (const auto& [action, seconds] : s.timeouts_s) o << " timeout " << action << " " << num(seconds) << "\n";
  o << " site " << optional(s.site.max_speed_mps) << " " << optional(s.site.max_climb_mps) << " "
    << optional(s.site.max_descent_mps) << "\n";
  if (const auto& g = s.site.geofence) {
    o << " fence " << optional(g->min_altitude_m) << " " << optional(g->max_altitude_m) << " " << g->upload << " "
      << g->max_altitude_at.has_value();
    for (const auto& [x, y] : g->polygon) o << " " << num(x) << "," << num(y);
    o << "\n";
  }
  if (s.gust) o << " gust " << num(s.gust->at_s) << " " << num(s.gust->for_s) << " " << vec(s.gust->velocity) << "\n";
}

void describe(std::ostream& o, const fleet::DroneType& t) {
  o << "type " << t.name << " " << t.adapter << " " << t.sensors << " " << t.generic << " "
    << num(t.limits.max_speed_mps) << " " << num(t.tolerance.horizontal_m) << "\n";
  for (const fleet::ActionSpec& a : t.actions)
    o << " action " << a.name << " " << ints(a.arities) << " " << static_cast<int>(a.action_class) << " " << a.params
      << "\n";
  for (const fleet::PropertySpec& p : t.properties)
    o << " property " << p.name << " " << static_cast<int>(p.type) << " " << p.unit << "\n";
}

void describe(std::ostream& o, const dex::Node& n) {
  o << "node " << n.meg << " " << n.drone << " " << n.internal << " " << static_cast<int>(n.kind) << " " << n.name
    << " | " << n.text << " | " << n.line << ":" << n.col << " control " << static_cast<int>(n.control) << " count "
    << n.count << " seconds " << num(n.seconds) << " scope " << n.scope << " cancels " << ints(n.cancels)
    << " waits " << n.waits << "/" << n.waits_count << " notify " << n.notify << " out " << ints(n.out) << " in "
    << n.exec_in << "/" << n.back_in << " reads " << ints(n.condition_reads) << "\n  ";
  for (const dex::Expr& a : n.args) describe(o, a);
  describe(o, n.condition);
  o << "\n";
}

/// Every member of a Mission, one line each, in a form a failed comparison shows readably.
std::string describe(const dex::Mission& m) {
  std::ostringstream o;
  o << "hash " << m.hash << "\nsource " << m.source << "\nself " << m.self << "\nfleet";
  for (const std::string& name : m.fleet) o << " " << name;
  o << "\nreads " << ints(m.reads) << "\nseparation " << num(m.separation.horizontal_m) << " "
    << num(m.separation.vertical_m) << "\npriorities " << ints(m.priorities.get()) << "\n";
  describe(o, m.settings);
  describe(o, m.type);
  for (const auto& set : m.drone_sets) o << "set " << ints(set.get()) << "\n";
  for (const dex::Node& n : m.nodes) describe(o, n);
  for (const dex::Arc& a : m.arcs)
    o << "arc " << a.from << " " << a.to << " " << static_cast<int>(a.kind) << " " << static_cast<int>(a.branch) << "\n";
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    if (m.find(m.nodes[i].meg, m.nodes[i].drone) != static_cast<int>(i)) o << "index misses node " << i << "\n";
  o << "indexed " << m.index.size() << "\n";
  return o.str();
}

/// Both ways of loading `c` give every drone the same mission, and share the fleet-wide tables.
void expect_memory_equals_files(const graph::Compilation& c) {
  std::vector<dex::Mission> read, built;
  std::vector<std::string> errors;
  ASSERT_TRUE(deploy::read_compiled_missions(c, read, errors)) << errors.front();
  ASSERT_TRUE(deploy::compiled_missions(c, built, errors)) << errors.front();
  ASSERT_EQ(built.size(), read.size());
  for (std::size_t d = 0; d < built.size(); ++d) {
    EXPECT_EQ(describe(built[d]), describe(read[d])) << "drone " << c.drone_name(static_cast<int>(d));
    EXPECT_TRUE(built[d].fleet.same_as(built[0].fleet));
    EXPECT_TRUE(built[d].priorities.same_as(built[0].priorities));
    // A drone set of the same drones is one table, whichever drone's mission names it.
    for (std::size_t s = 0; s < built[d].drone_sets.size(); ++s)
      for (std::size_t e = 0; e < built[0].drone_sets.size(); ++e) {
        if (built[d].drone_sets[s].get() != built[0].drone_sets[e].get()) continue;
        EXPECT_TRUE(built[d].drone_sets[s].same_as(built[0].drone_sets[e])) << "a set held twice";
      }
  }
}

// Every setting a file carries, the ones it leaves out (priority, where a limit was set),
// and a type's capabilities and tolerance.
const char* kEverySetting =
    "safety:\n"
    "  min_separation: {horizontal: 3.5, vertical: 1.25}\n"
    "  home_tolerance: 4.5\n"
    "  max_speed: 6\n"
    "  max_climb: 1.5\n"
    "  geofence:\n"
    "    polygon: [[-100, -100], [100, -100], [100, 100.5], [-100, 100]]\n"
    "    max_altitude: 60\n"
    "types:\n"
    "  DroneType2:\n"
    "    tolerance: {horizontal: 1.25, vertical: 0.75, speed: 0.5}\n";

TEST(MissionsBuiltInMemory, EqualTheFilesReadForEverySettingOfListing2) {
  std::string fleet = std::string(kEverySetting) + test::kListing2Fleet +
                      "    priority: 2\n"
                      "    signing: {key: 0f1e2d3c4b5a69788796a5b4c3d2e1f000112233445566778899aabbccddeeff, setup: true}\n"
                      "    announce_as_gcs: true\n"
                      "    gust: {at: 8, for: 10.5, velocity: [4, 0.25, 0]}\n";
  auto c = test::compile_mission(test::listing2_text(), fleet);
  ASSERT_TRUE(c);
  expect_memory_equals_files(*c);
}

TEST(MissionsBuiltInMemory, EqualTheFilesReadForEveryControlStructure) {
  auto c = test::compile_mission(
      test::read_text(std::string(EAMOS_SOURCE_DIR) + "/tests/deploy/missions/every_control_structure.eamos"));
  ASSERT_TRUE(c);
  expect_memory_equals_files(*c);
}

TEST(MissionsBuiltInMemory, EqualTheFilesReadForEveryStressShape) {
  for (stress::Shape shape : {stress::Shape::squads, stress::Shape::show, stress::Shape::cross}) {
    stress::StressOptions o;
    o.shape = shape;
    o.drones = 24;
    o.target_nodes = 1500;
    auto c = test::compile_mission(stress::generate_mission(o));
    ASSERT_TRUE(c);
    SCOPED_TRACE(stress::shape_name(shape));
    expect_memory_equals_files(*c);
  }
}

}  // namespace
}  // namespace eamos
