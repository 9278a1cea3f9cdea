// Reading valid fleet files: what each key of docs/fleet.md turns into.
#include <gtest/gtest.h>

#include "helpers.h"

namespace eamos::fleet {
namespace {

using test::parse;

const std::string kExample = std::string(EAMOS_TEST_DATA) + "/data/example.yaml";

TEST(Parse, DocumentedExampleLoadsWithoutDiagnostics) {
  Fleet fleet;
  Diagnostics diags;
  ASSERT_TRUE(load_fleet(kExample, fleet, diags)) << diags.format();
  EXPECT_TRUE(diags.items().empty()) << diags.format();
  EXPECT_EQ(fleet.path, kExample);
  EXPECT_EQ(fleet.types.size(), 2u);
  EXPECT_EQ(fleet.drones.size(), 3u);
  ASSERT_NE(fleet.source, nullptr);
}

TEST(Parse, ExampleFileIsTheOneDocsFleetMdShows) {
  SourceFile doc, example;
  std::string error;
  ASSERT_TRUE(read_source_file(std::string(EAMOS_SOURCE_DIR) + "/docs/fleet.md", doc, error)) << error;
  ASSERT_TRUE(read_source_file(kExample, example, error)) << error;
  std::size_t begin = doc.text.find("```yaml\n");
  ASSERT_NE(begin, std::string::npos);
  begin += 8;
  std::string shown = doc.text.substr(begin, doc.text.find("```", begin) - begin);
  // The data file starts with one comment line pointing back at the doc.
  EXPECT_EQ(example.text.substr(example.text.find('\n') + 1), shown);
}

TEST(Parse, MissingFileIsAnErrorNamingThePath) {
  Fleet fleet;
  Diagnostics diags;
  EXPECT_FALSE(load_fleet("/nonexistent/fleet.yaml", fleet, diags));
  ASSERT_EQ(diags.error_count(), 1u);
  EXPECT_NE(diags.items()[0].message.find("/nonexistent/fleet.yaml"), std::string::npos);
}

TEST(Parse, EmptyFileIsAnEmptyFleet) {
  for (const char* text : {"", "\n# only a comment\n", "types:\ndrones:\n"}) {
    auto p = parse(text);
    EXPECT_TRUE(p.ok) << p.diags.format();
    EXPECT_TRUE(p.fleet.types.empty());
    EXPECT_TRUE(p.fleet.drones.empty());
  }
}

TEST(Parse, HomeToleranceOfSafetyReachesEveryDronesSettings) {
  auto p = parse("safety:\n  home_tolerance: 5.5\ndrones:\n  A: {home: [0, 5, 0]}\n");
  ASSERT_TRUE(p.ok) << p.diags.format();
  EXPECT_EQ(p.fleet.settings_for("A", "Quad", 0).home_tolerance_m, 5.5);
  EXPECT_EQ(parse("drones:\n  A: {}\n").fleet.settings_for("A", "Quad", 0).home_tolerance_m, 3.0);
  EXPECT_FALSE(parse("safety:\n  home_tolerance: 0\n").ok);
}

TEST(Parse, CapabilitySubsetRemovesOtherActions) {
  auto p = parse("types:\n  Scout:\n    capabilities: [Arm, FlyTo, Hover]\n    sensors: 2\n");
  ASSERT_TRUE(p.ok) << p.diags.format();
  const DroneType& t = p.fleet.types.at("Scout");
  EXPECT_NE(t.find_action("Arm"), nullptr);
  EXPECT_NE(t.find_action("FlyTo"), nullptr);
  EXPECT_NE(t.find_action("Hover"), nullptr);
  EXPECT_EQ(t.find_action("Land"), nullptr);
  EXPECT_EQ(t.find_action("TakePicture"), nullptr);
  EXPECT_NE(t.find_action("Sensor2"), nullptr);
  EXPECT_EQ(t.actions.size(), 3u + 2u);
}

TEST(Parse, EveryPropertyStaysWhateverTheCapabilities) {
  auto p = parse("types:\n  Scout:\n    capabilities: []\n    sensors: 1\n");
  ASSERT_TRUE(p.ok) << p.diags.format();
  const DroneType& t = p.fleet.types.at("Scout");
  for (const auto& prop : standard_properties()) EXPECT_NE(t.find_property(prop.name), nullptr);
  EXPECT_NE(t.find_property("Sensor1"), nullptr);
  ASSERT_EQ(t.actions.size(), 1u);
  EXPECT_EQ(t.actions[0].name, "Sensor1");
}

TEST(Parse, TypeWithoutCapabilitiesHasAllStandardActions) {
  auto p = parse("types:\n  Scout:\n    sensors: 3\n");
  ASSERT_TRUE(p.ok) << p.diags.format();
  const DroneType& t = p.fleet.types.at("Scout");
  EXPECT_FALSE(t.generic);
  EXPECT_EQ(t.name, "Scout");
  EXPECT_EQ(t.actions.size(), standard_actions().size() + 3);
}

TEST(Parse, EmptyTypeEntryIsAStandardTypeDescribedByTheFile) {
  auto p = parse("types:\n  Scout:\n");
  ASSERT_TRUE(p.ok) << p.diags.format();
  EXPECT_FALSE(p.fleet.types.at("Scout").generic);
  EXPECT_EQ(p.fleet.types.at("Scout").sensors, 8);
}

TEST(Parse, TypeLimitsOverrideTheDefaultsOnlyWhereSet) {
  auto p = parse("types:\n  Lifter:\n    adapter: mavlink\n    limits:\n      max_speed: 4\n");
  ASSERT_TRUE(p.ok) << p.diags.format();
  const DroneType& t = p.fleet.types.at("Lifter");
  EXPECT_EQ(t.adapter, "mavlink");
  EXPECT_DOUBLE_EQ(t.limits.max_speed_mps, 4);
  EXPECT_DOUBLE_EQ(t.limits.max_climb_mps, Limits{}.max_climb_mps);
}

TEST(Parse, AllFiveLimitsAreRead) {
  auto p = parse("types:\n  S:\n    limits: {max_speed: 8, max_climb: 2.5, max_descent: 1.5, "
                 "max_accel: 3, max_altitude: 100}\n");
  ASSERT_TRUE(p.ok) << p.diags.format();
  const Limits& l = p.fleet.types.at("S").limits;
  EXPECT_DOUBLE_EQ(l.max_speed_mps, 8);
  EXPECT_DOUBLE_EQ(l.max_climb_mps, 2.5);
  EXPECT_DOUBLE_EQ(l.max_descent_mps, 1.5);
  EXPECT_DOUBLE_EQ(l.max_accel_mps2, 3);
  EXPECT_DOUBLE_EQ(l.max_altitude_m, 100);
}

TEST(Parse, SensorGradientParsed) {
  auto p = parse("drones:\n  Drone1:\n    sensors:\n      Sensor2: {value: 10, gradient: [0.5, -1, 2]}\n");
  ASSERT_TRUE(p.ok) << p.diags.format();
  const SensorModel& m = p.fleet.drones.at("Drone1").sensors.at("Sensor2");
  EXPECT_DOUBLE_EQ(m.base, 10);
  EXPECT_DOUBLE_EQ(m.gradient.x, 0.5);
  EXPECT_DOUBLE_EQ(m.gradient.y, -1);
  EXPECT_DOUBLE_EQ(m.gradient.z, 2);
}

TEST(Parse, PlainSensorNumberIsAConstant) {
  auto p = parse("drones:\n  Drone1:\n    sensors: {Sensor1: 120}\n");
  ASSERT_TRUE(p.ok) << p.diags.format();
  const SensorModel& m = p.fleet.drones.at("Drone1").sensors.at("Sensor1");
  EXPECT_DOUBLE_EQ(m.base, 120);
  EXPECT_DOUBLE_EQ(m.gradient.x, 0);
  EXPECT_DOUBLE_EQ(m.gradient.y, 0);
  EXPECT_DOUBLE_EQ(m.gradient.z, 0);
}

TEST(Parse, TypesAreReadBeforeDronesWhateverTheOrderInTheFile) {
  auto p = parse("drones:\n  Drone1:\n    sensors: {Sensor12: 1}\ntypes:\n  Big:\n    sensors: 12\n");
  EXPECT_TRUE(p.ok) << p.diags.format();
  EXPECT_EQ(p.fleet.drones.at("Drone1").sensors.count("Sensor12"), 1u);
}

TEST(Parse, DroneLocationsPointAtTheirNames) {
  auto p = parse("drones:\n  Drone1:\n    battery: 50\n  Drone2:\n");
  ASSERT_TRUE(p.ok) << p.diags.format();
  EXPECT_EQ(p.fleet.drone_locations.at("Drone1").line, 2);
  EXPECT_EQ(p.fleet.drone_locations.at("Drone1").col, 3);
  EXPECT_EQ(p.fleet.drone_locations.at("Drone2").line, 4);
  EXPECT_EQ(p.fleet.drones.count("Drone2"), 1u);
}

TEST(Parse, NegativeHomeCoordinatesAndFractionsAreFine) {
  auto p = parse("drones:\n  Drone1:\n    home: [-10.5, 1e1, 0]\n");
  ASSERT_TRUE(p.ok) << p.diags.format();
  EXPECT_DOUBLE_EQ(p.fleet.drones.at("Drone1").home.x, -10.5);
  EXPECT_DOUBLE_EQ(p.fleet.drones.at("Drone1").home.y, 10);
}

}  // namespace
}  // namespace eamos::fleet

namespace eamos::fleet {
namespace {

// The safety section and the keys `eamos verify` reads; their errors are golden files under
// tests/lang/diagnostics/fleet_*.
TEST(Safety, DefaultsWhenTheFileSaysNothing) {
  Fleet f;
  Diagnostics d;
  ASSERT_TRUE(parse_fleet(std::make_shared<SourceFile>(SourceFile{"f.yaml", ""}), f, d));
  EXPECT_EQ(f.safety.min_separation.horizontal_m, 2.0);
  EXPECT_EQ(f.safety.min_separation.vertical_m, 1.0);
  EXPECT_EQ(f.safety.battery_reserve_percent, 20.0);
  EXPECT_FALSE(f.safety.geofence);
  EXPECT_EQ(f.geofence_for("Drone1"), nullptr);
}

TEST(Safety, ReadsEveryKeyAndADroneFenceReplacesTheFleets) {
  const char* text =
      "safety:\n"
      "  min_separation: {horizontal: 3, vertical: 1.5}\n"
      "  battery_reserve: 25\n"
      "  max_speed: 5\n"
      "  geofence: {polygon: [[0, 0], [10, 0], [10, 10], [0, 10]], max_altitude: 30}\n"
      "drones:\n"
      "  Drone2:\n"
      "    geofence: {min_altitude: 2}\n"
      "    sensors:\n"
      "      Sensor1: {value: 4, range: [0, 9]}\n";
  Fleet f;
  Diagnostics d;
  ASSERT_TRUE(parse_fleet(std::make_shared<SourceFile>(SourceFile{"f.yaml", text}), f, d)) << d.format();
  EXPECT_EQ(f.safety.min_separation.horizontal_m, 3.0);
  EXPECT_EQ(f.safety.min_separation.vertical_m, 1.5);
  EXPECT_EQ(f.safety.battery_reserve_percent, 25.0);
  EXPECT_EQ(*f.safety.max_speed_mps, 5.0);
  const Geofence* g1 = f.geofence_for("Drone1");
  ASSERT_NE(g1, nullptr);
  EXPECT_TRUE(g1->contains(5, 5, 10));
  EXPECT_TRUE(g1->contains(10, 5, 10));  // on the boundary
  EXPECT_FALSE(g1->contains(11, 5, 10));
  EXPECT_FALSE(g1->contains(5, 5, 31));
  const Geofence* g2 = f.geofence_for("Drone2");
  ASSERT_NE(g2, nullptr);
  EXPECT_TRUE(g2->contains(100, 100, 3));  // its own fence has no polygon
  EXPECT_FALSE(g2->contains(0, 0, 1));
  const SensorRange* r = f.sensor_range("Drone2", "Sensor1");
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->low, 0.0);
  EXPECT_EQ(r->high, 9.0);
  EXPECT_EQ(f.drones.at("Drone2").sensors.at("Sensor1").base, 4.0);
}

}  // namespace
}  // namespace eamos::fleet

namespace eamos::fleet {
namespace {

TEST(SiteRules, EachDroneGetsItsFenceAndTheSitesSpeeds) {
  test::Parsed p = test::parse(
      "safety:\n"
      "  max_speed: 4\n"
      "  max_descent: 1\n"
      "  geofence: {polygon: [[0, 0], [10, 0], [10, 10]]}\n"
      "drones:\n"
      "  Drone2:\n"
      "    geofence: {polygon: [[0, 0], [5, 0], [5, 5]], max_altitude: 9}\n"
      "    gust: {at: 3, for: 2, velocity: [1, 0, 0]}\n");
  ASSERT_TRUE(p.ok) << p.diags.format();
  DroneSettings d1 = p.fleet.settings_for("Drone1", "Quad", 0);
  DroneSettings d2 = p.fleet.settings_for("Drone2", "Quad", 1);
  EXPECT_EQ(*d1.site.max_speed_mps, 4.0);
  EXPECT_EQ(*d2.site.max_descent_mps, 1.0);
  EXPECT_FALSE(d1.site.max_climb_mps);
  ASSERT_TRUE(d1.site.geofence && d2.site.geofence);
  EXPECT_EQ(d1.site.geofence->polygon.size(), 3u);
  EXPECT_EQ(*d2.site.geofence->max_altitude_m, 9.0);
  EXPECT_FALSE(d1.gust);
  ASSERT_TRUE(d2.gust);
  EXPECT_EQ(d2.gust->at_s, 3.0);
  EXPECT_EQ(d2.gust->velocity.x, 1.0);
}

TEST(SiteRules, AFenceIsGivenToTheAutopilotOnlyWhereUploadIsTrue) {
  test::Parsed p = test::parse(
      "safety:\n"
      "  geofence: {polygon: [[0, 0], [10, 0], [10, 10]], upload: true}\n"
      "drones:\n"
      "  Drone2:\n"
      "    geofence: {polygon: [[0, 0], [5, 0], [5, 5]]}\n");
  ASSERT_TRUE(p.ok) << p.diags.format();
  EXPECT_TRUE(p.fleet.settings_for("Drone1", "Quad", 0).site.geofence->upload);
  EXPECT_FALSE(p.fleet.settings_for("Drone2", "Quad", 1).site.geofence->upload);
}

TEST(SiteRules, AnUploadWithoutAPolygonOrNotABooleanIsAnErrorAtItsLine) {
  test::Parsed p = test::parse(
      "safety:\n"
      "  geofence: {max_altitude: 30, upload: true}\n"
      "drones:\n"
      "  Drone1:\n"
      "    geofence: {polygon: [[0, 0], [5, 0], [5, 5]], upload: maybe}\n");
  EXPECT_FALSE(p.ok);
  std::string all = p.diags.format();
  EXPECT_NE(all.find("fleet.yaml:2:13: error: upload of geofence of safety needs a polygon"), std::string::npos) << all;
  EXPECT_NE(all.find("fleet.yaml:5:59: error: upload of geofence of drone 'Drone1' must be true or false; got"),
            std::string::npos)
      << all;
}

TEST(SiteRules, ABadGustIsAnErrorAtItsLineWithEveryOtherError) {
  test::Parsed p = test::parse(
      "safety:\n"
      "  max_climb: sometimes\n"
      "drones:\n"
      "  Drone1:\n"
      "    gust: {at: -1, velocity: [1, 0]}\n");
  EXPECT_FALSE(p.ok);
  std::string all = p.diags.format();
  EXPECT_NE(all.find("fleet.yaml:2:14: error: max_climb of safety"), std::string::npos) << all;
  EXPECT_NE(all.find("velocity of gust of drone 'Drone1'"), std::string::npos) << all;
  EXPECT_NE(all.find("at of gust of drone 'Drone1' must be a mission time"), std::string::npos) << all;
  EXPECT_NE(all.find("needs `for` (s) and `velocity`"), std::string::npos) << all;
}

}  // namespace
}  // namespace eamos::fleet
