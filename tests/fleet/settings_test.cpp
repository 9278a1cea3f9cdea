// Fleet::type_for and Fleet::settings_for: what a mission's drone gets, with and without a file.
#include <gtest/gtest.h>

#include "helpers.h"

namespace eamos::fleet {
namespace {

using test::parse;

const char* kFleet = R"(types:
  Scout:
    sensors: 2
    limits: {max_speed: 8, max_climb: 2.5}
  Lifter:
    adapter: mavlink
    sensors: 0
drones:
  Drone1:
    home: [1, 2, 3]
    limits: {max_speed: 5}
    sensors: {Sensor1: 7, Sensor2: 9}
  Drone2:
    adapter: mavlink
    connection: udp://:14540
    sysid: 7
    battery: 60
    failsafe: return_home
    timeouts: {Takeoff: 40}
  Drone3:
    failsafe: hover
)";

TEST(Settings, UndescribedTypeIsGenericMultirotor) {
  Fleet fleet;
  DroneType t = fleet.type_for("Quad");
  EXPECT_TRUE(t.generic);
  EXPECT_EQ(t.name, "Quad");
  EXPECT_EQ(t.sensors, 8);
  EXPECT_EQ(t.actions.size(), generic_multirotor("Quad").actions.size());
}

TEST(Settings, DescribedTypeComesFromTheFile) {
  auto p = parse(kFleet);
  ASSERT_TRUE(p.ok) << p.diags.format();
  DroneType t = p.fleet.type_for("Scout");
  EXPECT_FALSE(t.generic);
  EXPECT_EQ(t.sensors, 2);
  EXPECT_TRUE(p.fleet.type_for("Other").generic);
}

TEST(Settings, DefaultHomeIsFiveMetresApartByDeclarationOrder) {
  Fleet fleet;
  for (int i = 0; i < 3; ++i) {
    Vec3 home = fleet.settings_for("D" + std::to_string(i), "Quad", i).home;
    EXPECT_DOUBLE_EQ(home.x, 0);
    EXPECT_DOUBLE_EQ(home.y, 5.0 * i);
    EXPECT_DOUBLE_EQ(home.z, 0);
  }
}

TEST(Settings, WithoutAFileADroneLandsOnFailureFliesInSimAndReadsNoSensors) {
  Fleet fleet;
  DroneSettings s = fleet.settings_for("Drone1", "Quad", 0);
  EXPECT_EQ(s.name, "Drone1");
  EXPECT_EQ(s.type, "Quad");
  EXPECT_EQ(s.failsafe, Failsafe::land);
  EXPECT_EQ(s.adapter, "sim");
  EXPECT_TRUE(s.sensors.empty());
  EXPECT_TRUE(s.connection.empty());
  EXPECT_EQ(s.sysid, 0);
  EXPECT_DOUBLE_EQ(s.battery_percent, 100);
  EXPECT_DOUBLE_EQ(s.limits.max_speed_mps, Limits{}.max_speed_mps);
}

TEST(Settings, DescribedHomeReplacesTheDefault) {
  auto p = parse(kFleet);
  Vec3 home = p.fleet.settings_for("Drone1", "Scout", 4).home;
  EXPECT_DOUBLE_EQ(home.x, 1);
  EXPECT_DOUBLE_EQ(home.y, 2);
  EXPECT_DOUBLE_EQ(home.z, 3);
}

TEST(Settings, DescribedDroneWithoutHomeKeepsTheDefaultHome) {
  auto p = parse(kFleet);
  EXPECT_DOUBLE_EQ(p.fleet.settings_for("Drone3", "Scout", 2).home.y, 10.0);
  EXPECT_EQ(p.fleet.settings_for("Drone3", "Scout", 2).failsafe, Failsafe::hover);
}

TEST(Settings, FileOverridesLimitsPerDrone) {
  auto p = parse(kFleet);
  DroneSettings one = p.fleet.settings_for("Drone1", "Scout", 0);
  EXPECT_DOUBLE_EQ(one.limits.max_speed_mps, 5);     // the drone's
  EXPECT_DOUBLE_EQ(one.limits.max_climb_mps, 2.5);   // the type's
  EXPECT_DOUBLE_EQ(one.limits.max_accel_mps2, Limits{}.max_accel_mps2);  // the default
  DroneSettings three = p.fleet.settings_for("Drone3", "Scout", 2);
  EXPECT_DOUBLE_EQ(three.limits.max_speed_mps, 8);
}

TEST(Settings, DroneLimitsOverrideWhicheverTypeTheMissionNames) {
  auto p = parse(kFleet);
  DroneSettings s = p.fleet.settings_for("Drone1", "Quad", 0);
  EXPECT_DOUBLE_EQ(s.limits.max_speed_mps, 5);
  EXPECT_DOUBLE_EQ(s.limits.max_climb_mps, Limits{}.max_climb_mps);
}

TEST(Settings, AdapterComesFromTheTypeUnlessTheDroneSetsIt) {
  auto p = parse(kFleet);
  EXPECT_EQ(p.fleet.settings_for("Drone3", "Lifter", 2).adapter, "mavlink");
  EXPECT_EQ(p.fleet.settings_for("Drone3", "Scout", 2).adapter, "sim");
  EXPECT_EQ(p.fleet.settings_for("Drone2", "Scout", 1).adapter, "mavlink");
}

TEST(Settings, ConnectionSysidBatteryFailsafeAndTimeoutsAreCopied) {
  auto p = parse(kFleet);
  DroneSettings s = p.fleet.settings_for("Drone2", "Scout", 1);
  EXPECT_EQ(s.connection, "udp://:14540");
  EXPECT_EQ(s.sysid, 7);
  EXPECT_DOUBLE_EQ(s.battery_percent, 60);
  EXPECT_EQ(s.failsafe, Failsafe::return_home);
  ASSERT_EQ(s.timeouts_s.count("Takeoff"), 1u);
  EXPECT_DOUBLE_EQ(s.timeouts_s.at("Takeoff"), 40);
  EXPECT_EQ(s.type, "Scout");
}

TEST(Settings, SensorsTheMissionTypeLacksAreDropped) {
  auto p = parse(kFleet);
  EXPECT_EQ(p.fleet.settings_for("Drone1", "Scout", 0).sensors.size(), 2u);
  EXPECT_TRUE(p.fleet.settings_for("Drone1", "Lifter", 0).sensors.empty());
}

TEST(Settings, CheckDroneReportsSensorsTheTypeLacksAtTheirKey) {
  auto p = parse(kFleet);
  Diagnostics diags;
  p.fleet.check_drone("Drone1", p.fleet.type_for("Scout"), diags);
  EXPECT_FALSE(diags.has_errors());
  p.fleet.check_drone("Drone1", p.fleet.type_for("Lifter"), diags);
  ASSERT_EQ(diags.error_count(), 2u);
  const Diagnostic& d = diags.items()[0];
  EXPECT_EQ(d.path, p.fleet.source->path);
  EXPECT_EQ(d.loc.line, 12);
  EXPECT_EQ(d.loc.col, 15);
  EXPECT_NE(d.message.find("has 0 sensors"), std::string::npos) << d.message;
}

TEST(Settings, FailsafeNamesAreTheFileSpelling) {
  EXPECT_STREQ(failsafe_name(Failsafe::land), "land");
  EXPECT_STREQ(failsafe_name(Failsafe::return_home), "return_home");
  EXPECT_STREQ(failsafe_name(Failsafe::hover), "hover");
}

// Announcing a ground station hides the real one's loss from PX4: only a drone whose entry
// says so does it.
TEST(Settings, AnnounceAsGcsIsOnlyForTheDronesThatAskAndTakesOnlyTrueOrFalse) {
  auto p = parse("drones:\n  D1: {adapter: mavlink, announce_as_gcs: true}\n  D2: {adapter: mavlink}\n");
  ASSERT_TRUE(p.ok);
  EXPECT_TRUE(p.fleet.drones.at("D1").announce_as_gcs);
  EXPECT_FALSE(p.fleet.drones.at("D2").announce_as_gcs);
  auto bad = parse("drones:\n  D1: {announce_as_gcs: [yes]}\n  D2: {announce_as_gcs: sometimes}\n");
  EXPECT_FALSE(bad.ok);
  ASSERT_EQ(bad.diags.error_count(), 2u);
  Diagnostic d = test::first_error(bad.diags);
  EXPECT_EQ(d.loc.line, 2);
  EXPECT_NE(d.message.find("announce_as_gcs of drone 'D1' must be true or false; got "), std::string::npos) << d.message;
}

TEST(Settings, ATypesGoalToleranceGoesToItsDronesAndOthersKeepTheDefault) {
  auto p = parse("types:\n  Lifter:\n    tolerance: {horizontal: 1.5, vertical: 0.8}\n"
                 "drones:\n  D1: {home: [0, 0, 0]}\n");
  ASSERT_TRUE(p.ok) << p.diags.format();
  DroneSettings lifter = p.fleet.settings_for("D1", "Lifter", 0);
  EXPECT_DOUBLE_EQ(lifter.tolerance.horizontal_m, 1.5);
  EXPECT_DOUBLE_EQ(lifter.tolerance.vertical_m, 0.8);
  EXPECT_DOUBLE_EQ(lifter.tolerance.settled_mps, 0.3);  // not given: the default
  DroneSettings quad = p.fleet.settings_for("D1", "Quad", 0);
  EXPECT_DOUBLE_EQ(quad.tolerance.horizontal_m, 0.5);
  EXPECT_DOUBLE_EQ(quad.tolerance.vertical_m, 0.3);
}

}  // namespace
}  // namespace eamos::fleet
