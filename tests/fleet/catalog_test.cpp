// The platform catalog: what every generic drone can do and how sensors become capabilities.
#include <gtest/gtest.h>

#include <algorithm>

#include "fleet/catalog.h"

namespace eamos::fleet {
namespace {

const ActionSpec* standard(const std::string& name) {
  for (const auto& a : standard_actions())
    if (a.name == name) return &a;
  return nullptr;
}

TEST(Catalog, StandardActionsAcceptTheirDocumentedArgumentCounts) {
  using Arities = std::vector<int>;
  EXPECT_EQ(standard("Arm")->arities, Arities{0});
  EXPECT_EQ(standard("Takeoff")->arities, Arities{1});
  EXPECT_EQ(standard("FlyTo")->arities, Arities{3});
  EXPECT_EQ(standard("FlyBy")->arities, Arities{3});
  EXPECT_EQ(standard("FlyByZ")->arities, Arities{1});
  EXPECT_EQ(standard("Hover")->arities, (Arities{0, 1}));
  EXPECT_EQ(standard("Orbit")->arities, (Arities{0, 1}));
  EXPECT_EQ(standard("ReturnHome")->arities, Arities{0});
}

TEST(Catalog, ArmingIsSystemPicturesArePayloadFlightIsMotion) {
  EXPECT_EQ(standard("Arm")->action_class, ActionClass::system);
  EXPECT_EQ(standard("Disarm")->action_class, ActionClass::system);
  EXPECT_EQ(standard("TakePicture")->action_class, ActionClass::payload);
  for (const char* motion : {"Takeoff", "Land", "FlyTo", "FlyByX", "Hover", "Orbit", "ReturnHome"})
    EXPECT_EQ(standard(motion)->action_class, ActionClass::motion) << motion;
}

TEST(Catalog, SensorReadsAreNotStandardActions) {
  EXPECT_EQ(standard("Sensor1"), nullptr);
  EXPECT_EQ(standard_actions().size(), 13u);
}

TEST(Catalog, PositionIsInMetresBatteryInPercentStatesAreBoolean) {
  DroneType t = generic_multirotor("Quad");
  EXPECT_EQ(t.find_property("X")->unit, "m");
  EXPECT_EQ(t.find_property("Z")->type, ValueType::number);
  EXPECT_EQ(t.find_property("Battery")->unit, "%");
  EXPECT_EQ(t.find_property("Armed")->type, ValueType::boolean);
  EXPECT_EQ(t.find_property("Landed")->type, ValueType::boolean);
}

TEST(Catalog, GenericMultirotorHasEveryStandardActionAndEightSensors) {
  DroneType t = generic_multirotor("Quad");
  EXPECT_EQ(t.name, "Quad");
  EXPECT_TRUE(t.generic);
  EXPECT_EQ(t.adapter, "sim");
  EXPECT_EQ(t.sensors, 8);
  for (const auto& a : standard_actions()) EXPECT_NE(t.find_action(a.name), nullptr) << a.name;
  EXPECT_DOUBLE_EQ(t.limits.max_speed_mps, Limits{}.max_speed_mps);
}

TEST(Catalog, SensorKIsANoArgumentPayloadActionAndANumberProperty) {
  DroneType t = generic_multirotor("Quad");
  const ActionSpec* read = t.find_action("Sensor8");
  ASSERT_NE(read, nullptr);
  EXPECT_EQ(read->action_class, ActionClass::payload);
  EXPECT_EQ(read->arities, std::vector<int>{0});
  ASSERT_NE(t.find_property("Sensor8"), nullptr);
  EXPECT_EQ(t.find_property("Sensor8")->type, ValueType::number);
}

TEST(Catalog, SensorBeyondTheTypesCountIsNoCapability) {
  DroneType t = generic_multirotor("Quad");
  EXPECT_EQ(t.find_action("Sensor9"), nullptr);
  EXPECT_EQ(t.find_property("Sensor9"), nullptr);
  EXPECT_EQ(t.find_action("Sensor0"), nullptr);
}

TEST(Catalog, SetSensorsReplacesTheSensorSpecs) {
  DroneType t = generic_multirotor("Quad");
  set_sensors(t, 2);
  EXPECT_EQ(t.sensors, 2);
  EXPECT_NE(t.find_action("Sensor2"), nullptr);
  EXPECT_EQ(t.find_action("Sensor3"), nullptr);
  EXPECT_EQ(t.find_property("Sensor3"), nullptr);
  EXPECT_EQ(t.actions.size(), standard_actions().size() + 2);
  EXPECT_EQ(t.properties.size(), standard_properties().size() + 2);
}

TEST(Catalog, SensorIndexAcceptsOnlyCanonicalNamesWithinTheCount) {
  EXPECT_EQ(sensor_index("Sensor1", 8), 1);
  EXPECT_EQ(sensor_index("Sensor12", 12), 12);
  EXPECT_EQ(sensor_index("Sensor9", 8), 0);
  EXPECT_EQ(sensor_index("Sensor0", 8), 0);
  EXPECT_EQ(sensor_index("Sensor01", 8), 0);
  EXPECT_EQ(sensor_index("Sensor", 8), 0);
  EXPECT_EQ(sensor_index("sensor1", 8), 0);
  EXPECT_EQ(sensor_index("Sensor1x", 8), 0);
  EXPECT_EQ(sensor_index("Sensor-1", 8), 0);
  EXPECT_EQ(sensor_index("Sensor99999999999999999999", 8), 0);
}

TEST(Catalog, CapabilityNamesListActionsPropertiesAndEachSensorOnce) {
  DroneType t = generic_multirotor("Quad");
  std::vector<std::string> names = t.capability_names();
  auto count = [&](const std::string& n) { return std::count(names.begin(), names.end(), n); };
  EXPECT_EQ(count("FlyTo"), 1);
  EXPECT_EQ(count("Battery"), 1);
  EXPECT_EQ(count("Sensor3"), 1);
  EXPECT_EQ(names.size(), standard_actions().size() + standard_properties().size() + 8);
}

}  // namespace
}  // namespace eamos::fleet
