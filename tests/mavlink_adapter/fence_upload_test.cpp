// The mission's fence given to the autopilot's own fence (geofence `upload: true`): the
// corners and parameters the adapter computes (unit cases), and the upload against the
// sim-vehicle playing PX4 and ArduPilot over loopback UDP (real time sped up 4×), with the
// vehicle's refusals, losses and a read back that differs.
#include <gtest/gtest.h>

#include <string>

#include "flight.h"
#include "mavlink/enums.h"
#include "mavlink_adapter/fence_upload.h"
#include "mavlink_adapter/telemetry.h"

namespace eamos::mavlink_adapter {
namespace {

using test::Flight;
using test::kSpeed;

fleet::Geofence fence(bool upload = true) {
  fleet::Geofence g;
  g.polygon = {{-20, -10}, {30, -10}, {30, 40}, {-20, 40}};
  g.max_altitude_m = 25.0;
  g.upload = upload;
  return g;
}

const Autopilot& px4() { return *autopilot_for(mavlink::autopilot::PX4); }
const Autopilot& ardupilot() { return *autopilot_for(mavlink::autopilot::ARDUPILOTMEGA); }

// Where a fence item lies in the mission frame, for a vehicle whose local origin is `origin`
// and whose home is `home`.
fleet::Vec3 mission_point(const mavlink::MissionItemInt& item, GlobalOrigin origin, fleet::Vec3 home) {
  fleet::Vec3 ned = north_east_between(origin.lat_e7, origin.lon_e7, item.x, item.y);
  return ned_to_mission({ned.x, ned.y, 0}, home);
}

const FenceParam* find(const AutopilotFence& f, const std::string& name) {
  for (const FenceParam& p : f.params)
    if (p.name == name) return &p;
  return nullptr;
}

TEST(AutopilotFence, CornersLieWhereTheMissionFramePutsThemFromTheVehiclesOrigin) {
  GlobalOrigin origin{-353632620, 1491652370};
  fleet::Vec3 home{5, -3, 2};
  AutopilotFence f = autopilot_fence(px4(), fence(), home, fleet::Failsafe::land, origin, 7);
  ASSERT_EQ(f.items.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const mavlink::MissionItemInt& item = f.items[i];
    EXPECT_EQ(item.seq, i);
    EXPECT_EQ(item.command, mavlink::cmd::NAV_FENCE_POLYGON_VERTEX_INCLUSION);
    EXPECT_EQ(item.param[0], 4.0f);  // the polygon's vertex count
    EXPECT_EQ(item.mission_type, mavlink::mission_type::FENCE);
    EXPECT_EQ(item.target_system, 7);
    fleet::Vec3 p = mission_point(item, origin, home);
    EXPECT_NEAR(p.x, fence().polygon[i].first, 0.02) << i;
    EXPECT_NEAR(p.y, fence().polygon[i].second, 0.02) << i;
  }
}

TEST(AutopilotFence, ArduPilotGetsPolygonCeilingAboveHomeAndTheFailsafesActionWithTheSwitchLast) {
  AutopilotFence f = autopilot_fence(ardupilot(), fence(), {0, 0, 2}, fleet::Failsafe::return_home, {}, 1);
  ASSERT_EQ(f.params.size(), 4u);
  EXPECT_EQ(f.params.back().name, "FENCE_ENABLE");
  EXPECT_EQ(f.params.back().value, 1.0f);
  EXPECT_EQ(find(f, "FENCE_TYPE")->value, 5.0f);  // polygon 4 + maximum altitude 1
  EXPECT_EQ(find(f, "FENCE_ALT_MAX")->value, 23.0f);
  EXPECT_FALSE(find(f, "FENCE_ALT_MAX")->integer);
  EXPECT_EQ(find(f, "FENCE_ACTION")->value, 1.0f);  // RTL or land
  fleet::Geofence no_ceiling = fence();
  no_ceiling.max_altitude_m.reset();
  AutopilotFence g = autopilot_fence(ardupilot(), no_ceiling, {}, fleet::Failsafe::land, {}, 1);
  EXPECT_EQ(find(g, "FENCE_TYPE")->value, 4.0f);
  EXPECT_EQ(find(g, "FENCE_ALT_MAX"), nullptr);
  EXPECT_EQ(find(g, "FENCE_ACTION")->value, 2.0f);  // land
}

TEST(AutopilotFence, Px4GetsGfActionAndItsVerticalDistanceFromHome) {
  AutopilotFence f = autopilot_fence(px4(), fence(), {0, 0, 0}, fleet::Failsafe::hover, {}, 1);
  ASSERT_EQ(f.params.size(), 2u);
  EXPECT_EQ(find(f, "GF_MAX_VER_DIST")->value, 25.0f);
  EXPECT_EQ(find(f, "GF_ACTION")->value, 2.0f);  // hold
  EXPECT_TRUE(find(f, "GF_ACTION")->integer);
}

TEST(AutopilotFence, AReadBackIsComparedCornerByCorner) {
  AutopilotFence f = autopilot_fence(px4(), fence(), {}, fleet::Failsafe::land, {473977420, 85455940}, 1);
  std::vector<mavlink::MissionItemInt> read = f.items;
  read[2].x += 1;  // a double's rounding: the same corner
  EXPECT_EQ(compare_fence(f.items, read), "");
  read[2].x += 100;
  EXPECT_NE(compare_fence(f.items, read).find("fence item 2 lies at (47.39811"), std::string::npos)
      << compare_fence(f.items, read);
  read.pop_back();
  EXPECT_EQ(compare_fence(f.items, read), "it holds 3 fence item(s), 4 were sent");
}

// --- against the sim-vehicle ---------------------------------------------------------------

void with_fence(fleet::DroneSettings& s, fleet::Failsafe failsafe = fleet::Failsafe::land) {
  s.site.geofence = fence();
  s.failsafe = failsafe;
}

TEST(MavlinkFenceUpload, ArmWaitsUntilPx4HoldsTheMissionsFenceWhereTheMissionPutsIt) {
  test::VehicleThread vehicle(25491, 1, kSpeed);
  Flight f(25491, {}, [](fleet::DroneSettings& s) { with_fence(s); });
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  auto held = vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.fence(); });
  ASSERT_EQ(held.size(), 4u);
  // Read by the vehicle's own earth model (home at the mission's origin): the mission's
  // corners, to the centimetres by which the two models differ over 50 m.
  for (std::size_t i = 0; i < 4; ++i) {
    auto [x, y] = vehicle.inspect([&](sim_vehicle::SimVehicle& v) { return v.local_of(held[i].x, held[i].y); });
    EXPECT_NEAR(x, fence().polygon[i].first, 0.1) << i;
    EXPECT_NEAR(y, fence().polygon[i].second, 0.1) << i;
  }
  EXPECT_EQ(vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.param("GF_ACTION"); }), 5.0);
  EXPECT_EQ(vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.param("GF_MAX_VER_DIST"); }), 25.0);
}

TEST(MavlinkFenceUpload, ArduPilotAskingWithTheOlderRequestGetsTheFenceAndItsSwitch) {
  test::VehicleThread vehicle(25492, 1, kSpeed, sim_vehicle::ardupilot_dialect());
  Flight f(25492, {}, [](fleet::DroneSettings& s) { with_fence(s, fleet::Failsafe::return_home); });
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  EXPECT_EQ(vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.fence().size(); }), 4u);
  EXPECT_EQ(vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.fence_requests(); }), 4);
  EXPECT_EQ(vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.param("FENCE_ENABLE"); }), 1.0);
  EXPECT_EQ(vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.param("FENCE_TYPE"); }), 5.0);
  EXPECT_EQ(vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.param("FENCE_ALT_MAX"); }), 25.0);
  EXPECT_EQ(vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.param("FENCE_ACTION"); }), 1.0);
}

TEST(MavlinkFenceUpload, WithoutUploadTheAutopilotIsLeftAlone) {
  test::VehicleThread vehicle(25493, 1, kSpeed);
  Flight f(25493, {}, [](fleet::DroneSettings& s) { s.site.geofence = fence(false); });
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  EXPECT_TRUE(vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.fence().empty(); }));
  EXPECT_FALSE(vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.param("GF_ACTION").has_value(); }));
}

TEST(MavlinkFenceUpload, LostCountsAreSentAgainUntilTheVehicleAnswers) {
  sim_vehicle::VehicleOptions o;
  o.fence_counts_ignored = 2;
  test::VehicleThread vehicle(25494, kSpeed, o);
  MavlinkOptions options;
  options.fence_reply_s = 0.25;
  Flight f(25494, options, [](fleet::DroneSettings& s) { with_fence(s); });
  ASSERT_TRUE(f.drone) << f.created.message;
  ASSERT_EQ(f.fly("Arm").outcome, mid::Outcome::succeeded);
  EXPECT_EQ(vehicle.inspect([](sim_vehicle::SimVehicle& v) { return v.fence().size(); }), 4u);
}

// Each way the vehicle may not hold the fence: Arm fails, refused, with the vehicle's reason,
// and the vehicle stays disarmed.
struct Refusal {
  const char* name;
  int port;  ///< each case its own: ctest runs them side by side
  std::function<void(sim_vehicle::VehicleOptions&)> vehicle;
  const char* reason;
};
void PrintTo(const Refusal& r, std::ostream* os) { *os << r.name; }

class MavlinkFenceRefused : public ::testing::TestWithParam<Refusal> {};

TEST_P(MavlinkFenceRefused, ArmFailsWithTheReasonAndTheVehicleStaysDisarmed) {
  sim_vehicle::VehicleOptions o;
  GetParam().vehicle(o);
  test::VehicleThread vehicle(GetParam().port, kSpeed, o);
  MavlinkOptions options;
  options.fence_reply_s = 0.25;
  Flight f(GetParam().port, options, [](fleet::DroneSettings& s) { with_fence(s); });
  ASSERT_TRUE(f.drone) << f.created.message;
  mid::ActionEnd e = f.fly("Arm");
  EXPECT_EQ(e.outcome, mid::Outcome::failed);
  EXPECT_EQ(e.failure, mid::FailureReason::refused);
  EXPECT_NE(e.reason.find("the autopilot does not hold the mission's fence (geofence upload: true): "),
            std::string::npos)
      << e.reason;
  EXPECT_NE(e.reason.find(GetParam().reason), std::string::npos) << e.reason;
  EXPECT_FALSE(f.drone->state().armed);
  EXPECT_EQ(vehicle.inspect([](sim_vehicle::SimVehicle& v) {
              return v.received(mavlink::cmd::COMPONENT_ARM_DISARM);
            }),
            0);
}

INSTANTIATE_TEST_SUITE_P(
    Vehicles, MavlinkFenceRefused,
    ::testing::Values(
        Refusal{"NoRoom", 25495, [](sim_vehicle::VehicleOptions& o) { o.fence_capacity = 3; },
                "PX4 refused the fence: MAV_MISSION_NO_SPACE"},
        Refusal{"NoFence", 25496, [](sim_vehicle::VehicleOptions& o) { o.fence_capacity = 0; },
                "PX4 never sent its request for the first fence corner (MISSION_REQUEST_INT) after "
                "MISSION_COUNT in 5 tries"},
        Refusal{"ReadBackDiffers", 25497, [](sim_vehicle::VehicleOptions& o) { o.fence_read_back_shift_e7 = 1000; },
                "the fence read back from PX4 differs: fence item 0 lies at"},
        Refusal{"ParameterKept", 25498, [](sim_vehicle::VehicleOptions& o) { o.read_only_params = {"GF_ACTION"}; },
                "PX4 kept GF_ACTION at 0 when set to 5"}),
    [](const ::testing::TestParamInfo<Refusal>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace eamos::mavlink_adapter
