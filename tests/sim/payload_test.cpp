// Payload actions: TakePicture and SensorK reads run beside motion and never preempt it;
// sensors read base + gradient · position.
#include <gtest/gtest.h>

#include <cmath>

#include "helpers.h"

namespace eamos::sim {
namespace {

using mid::Outcome;

class Payload : public test::SimTest {};

TEST_F(Payload, PayloadRunsBesideMotion) {
  airborne(5);
  auto fly = start("FlyByX", {40});
  loop.run_until(loop.now() + 1);
  test::Result picture = run("TakePicture");
  test::Result reading = run("Sensor1");
  EXPECT_EQ(picture.end.outcome, Outcome::succeeded);
  EXPECT_EQ(reading.end.outcome, Outcome::succeeded);
  EXPECT_FALSE(fly->ended);  // still flying
  run_until_ended(*fly);
  EXPECT_EQ(fly->end.outcome, Outcome::succeeded);
  EXPECT_DOUBLE_EQ(d().state().x, 40.0);
}

TEST_F(Payload, TakePictureTakesHalfASecondAndCounts) {
  double t0 = loop.now();
  test::Result r = run("TakePicture");
  EXPECT_EQ(r.end.outcome, Outcome::succeeded);
  EXPECT_DOUBLE_EQ(r.t - t0, 0.5);
  EXPECT_FALSE(r.end.value.has_value());
  run("TakePicture");
  EXPECT_EQ(d().state().pictures, 2);
}

TEST_F(Payload, SensorValueFollowsGradient) {
  config.sensors["Sensor2"] = {10.0, {0.5, 0, -1}};
  airborne(4);
  test::Result at_home = run("Sensor2");
  ASSERT_TRUE(at_home.end.value.has_value());
  EXPECT_DOUBLE_EQ(*at_home.end.value, 10.0 + 0.5 * 0 - 1 * 4);
  ASSERT_EQ(run("FlyByX", {6}).end.outcome, Outcome::succeeded);
  test::Result east = run("Sensor2");
  EXPECT_DOUBLE_EQ(*east.end.value, 10.0 + 0.5 * 6 - 1 * 4);
  EXPECT_DOUBLE_EQ(d().state().sensors.at("Sensor2"), 9.0);  // the state shows it live
}

TEST_F(Payload, ConstantSensorAndUndescribedSensors) {
  config.sensors["Sensor1"] = {120.0, {}};
  test::Result r = run("Sensor1");
  EXPECT_DOUBLE_EQ(*r.end.value, 120.0);
  mid::DroneState s = d().state();
  ASSERT_EQ(s.sensors.size(), 8u);  // every sensor of the generic type
  EXPECT_DOUBLE_EQ(s.sensors.at("Sensor1"), 120.0);
  EXPECT_DOUBLE_EQ(s.sensors.at("Sensor8"), 0.0);
}

// Twelve sensors: a state lists them in name order (Sensor10 before Sensor2), each with its
// own model's reading, as the state built at every motion step does.
TEST_F(Payload, AStateWithTenOrMoreSensorsGivesEachItsOwnReading) {
  fleet::set_sensors(type, 12);
  config.sensors["Sensor2"] = {2.0, {}};
  config.sensors["Sensor10"] = {10.0, {1, 0, 0}};
  config.sensors["Sensor12"] = {12.0, {}};
  airborne(4);
  ASSERT_EQ(run("FlyByX", {3}).end.outcome, Outcome::succeeded);
  mid::DroneState s = d().state();
  ASSERT_EQ(s.sensors.size(), 12u);
  std::vector<std::string> names;
  for (const auto& [name, value] : s.sensors) names.push_back(name);
  EXPECT_EQ(names[1], "Sensor10");
  EXPECT_EQ(names[4], "Sensor2");
  EXPECT_DOUBLE_EQ(s.sensors.at("Sensor2"), 2.0);
  EXPECT_DOUBLE_EQ(s.sensors.at("Sensor10"), 13.0);
  EXPECT_DOUBLE_EQ(s.sensors.at("Sensor12"), 12.0);
  EXPECT_DOUBLE_EQ(s.sensors.at("Sensor11"), 0.0);
  EXPECT_DOUBLE_EQ(*run("Sensor10").end.value, 13.0);
}

// A motion step refills the state it publishes in place and works out only the readings
// that follow the position: every published state must still carry every sensor's reading.
TEST_F(Payload, EveryPublishedStateCarriesEachSensorsReadingWhileTheDroneMoves) {
  config.sensors["Sensor1"] = {120.0, {}};
  config.sensors["Sensor2"] = {10.0, {0.5, 0, -1}};
  int states = 0;
  d().subscribe([&states](const mid::DroneState& s) {
    ++states;
    EXPECT_DOUBLE_EQ(s.sensors.at("Sensor1"), 120.0);
    EXPECT_DOUBLE_EQ(s.sensors.at("Sensor2"), 10.0 + 0.5 * s.x - s.z);
    EXPECT_DOUBLE_EQ(s.sensors.at("Sensor3"), 0.0);
  });
  airborne(4);
  ASSERT_EQ(run("FlyByX", {6}).end.outcome, Outcome::succeeded);
  EXPECT_GT(states, 40);  // a state per step of a climb and a flight of several seconds
}

// A reading is base + gradient · position: for a base of -0 that is +0 wherever the drone
// stands, so such a sensor is no constant to copy (its -0 would show in a trace).
TEST_F(Payload, ASensorOfBaseMinusZeroReadsPlusZeroAsItsFormulaGives) {
  config.sensors["Sensor1"] = {-0.0, {}};
  airborne(4);
  ASSERT_EQ(run("FlyByX", {6}).end.outcome, Outcome::succeeded);
  EXPECT_FALSE(std::signbit(d().state().sensors.at("Sensor1")));
  EXPECT_FALSE(std::signbit(*run("Sensor1").end.value));
}

TEST_F(Payload, SensorReadIsShortAndNeedsNoArming) {
  double t0 = loop.now();
  test::Result r = run("Sensor3");
  EXPECT_EQ(r.end.outcome, Outcome::succeeded);
  EXPECT_DOUBLE_EQ(r.t - t0, 0.1);
}

TEST_F(Payload, CancelledPictureDoesNotCount) {
  auto picture = start("TakePicture");
  loop.run_until(0.2);
  EXPECT_TRUE(d().cancel(picture->id));
  loop.run_until(2.0);
  EXPECT_EQ(picture->end.outcome, Outcome::cancelled);
  EXPECT_EQ(d().state().pictures, 0);
}

}  // namespace
}  // namespace eamos::sim
