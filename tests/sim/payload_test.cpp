// Payload actions: TakePicture and SensorK reads run beside motion and never preempt it;
// sensors read base + gradient · position.
#include <gtest/gtest.h>

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
