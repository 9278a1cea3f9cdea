// What the simulator costs and how repeatable it is: idle drones schedule nothing, a minute of
// mission is a bounded number of events on virtual time, and the same inputs give the same
// state sequence. Time is asserted on the virtual clock only, never on the wall.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "helpers.h"
#include "mid/adapter_registry.h"
#include "sim/sim_adapter.h"

namespace eamos::sim {
namespace {

using mid::Outcome;

TEST(Cost, IdleDronesScheduleNoSteps) {
  mid::EventLoop loop;
  std::vector<std::unique_ptr<SimDrone>> drones;
  for (int i = 0; i < 50; ++i) {
    fleet::DroneSettings s = test::settings("Drone" + std::to_string(i + 1));
    s.home = {0, 5.0 * i, 0};
    drones.push_back(std::make_unique<SimDrone>(s, fleet::generic_multirotor("Quad"), loop));
    drones.back()->subscribe([](const mid::DroneState&) {});
  }
  EXPECT_EQ(loop.size(), 0u);
  loop.run_until(3600);
  EXPECT_EQ(loop.events_run(), 0u);

  // One drone flies; the 49 others still take no step.
  drones[0]->start({"Arm", {}}, [&](const mid::ActionEnd&) {
    drones[0]->start({"Takeoff", {5}}, nullptr);
  });
  loop.run_until(3620);
  EXPECT_GT(drones[0]->steps(), 0u);
  for (size_t i = 1; i < drones.size(); ++i) EXPECT_EQ(drones[i]->steps(), 0u);
}

TEST(Cost, SteppingStopsWhenTheMotionEnds) {
  mid::EventLoop loop;
  SimDrone drone(test::settings(), fleet::generic_multirotor("Quad"), loop);
  bool took_off = false;
  drone.start({"Arm", {}}, [&](const mid::ActionEnd&) {
    drone.start({"Takeoff", {3}}, [&](const mid::ActionEnd& e) {
      took_off = e.outcome == Outcome::succeeded;
    });
  });
  loop.run_until(60);
  ASSERT_TRUE(took_off);
  std::uint64_t steps = drone.steps();
  EXPECT_GT(steps, 0u);
  EXPECT_LE(steps, 20u * 3u);  // 3 m at up to 3 m/s, 20 steps a second
  loop.run_until(600);
  EXPECT_EQ(drone.steps(), steps);  // hovering: no more steps
}

// A scripted minute: arm, take off, fly out, orbit, picture, land, disarm. Returns every
// published state, and checks the script's outcomes on the way.
struct Trace {
  std::vector<mid::DroneState> states;
  double end_time = 0;
  std::uint64_t events = 0;
};

Trace sixty_second_mission() {
  mid::EventLoop loop;
  mid::AdapterRegistry registry;
  register_adapter(registry);
  fleet::DroneSettings s1 = test::settings("Drone1");
  fleet::DroneSettings s2 = test::settings("Drone2");
  s2.home = {0, 5, 0};
  s2.sensors["Sensor1"] = {100, {1, 0, 0}};
  auto type = fleet::generic_multirotor("Quad");
  auto d1 = registry.create("sim", s1, type, loop).drone;
  auto d2 = registry.create("sim", s2, type, loop).drone;
  Trace trace;
  for (auto* d : {d1.get(), d2.get()})
    d->subscribe([&](const mid::DroneState& s) { trace.states.push_back(s); });

  // Each drone runs its script one action after the other, as a DEX would.
  struct Script {
    mid::Drone* drone;
    std::vector<mid::ActionRequest> steps;
    size_t next = 0;
  };
  std::vector<Script> scripts = {
      {d1.get(), {{"Arm", {}}, {"Takeoff", {5}}, {"FlyTo", {30, 0, 5}}, {"Hover", {20}},
                  {"TakePicture", {}}, {"ReturnHome", {}}, {"Disarm", {}}}},
      {d2.get(), {{"Arm", {}}, {"Takeoff", {8}}, {"FlyByX", {10}}, {"Sensor1", {}},
                  {"Hover", {30}}, {"Land", {}}, {"Disarm", {}}}},
  };
  int running = 2;
  std::function<void(Script&)> next = [&](Script& sc) {
    if (sc.next == sc.steps.size()) {
      if (--running == 0) loop.stop();
      return;
    }
    const mid::ActionRequest& r = sc.steps[sc.next++];
    sc.drone->start(r, [&, name = r.name](const mid::ActionEnd& e) {
      EXPECT_EQ(e.outcome, Outcome::succeeded) << sc.drone->name() << " " << name << ": " << e.reason;
      next(sc);
    });
  };
  for (auto& sc : scripts) next(sc);
  loop.run_until(600);
  trace.end_time = loop.now();
  trace.events = loop.events_run();
  EXPECT_EQ(running, 0);
  EXPECT_TRUE(d1->state().landed);
  EXPECT_EQ(d1->state().pictures, 1);
  return trace;
}

TEST(Cost, SixtySecondMissionRunsInMilliseconds) {
  Trace t = sixty_second_mission();
  // About a minute of mission time ...
  EXPECT_GT(t.end_time, 40.0);
  EXPECT_LT(t.end_time, 80.0);
  // ... costs no more than two drones stepping at 20 Hz the whole time, plus the actions:
  // virtual time skips every idle gap, so the run takes as long as these events do.
  EXPECT_LT(t.events, static_cast<std::uint64_t>(2 * 20 * t.end_time + 200));
}

TEST(Cost, SameInputsGiveIdenticalStateSequence) {
  Trace a = sixty_second_mission();
  Trace b = sixty_second_mission();
  ASSERT_EQ(a.states.size(), b.states.size());
  ASSERT_GT(a.states.size(), 500u);
  for (size_t i = 0; i < a.states.size(); ++i) {
    const mid::DroneState& x = a.states[i];
    const mid::DroneState& y = b.states[i];
    // Bit-for-bit: the same operations in the same order, no tolerance needed.
    ASSERT_TRUE(x.t == y.t && x.x == y.x && x.y == y.y && x.z == y.z && x.battery == y.battery &&
                x.armed == y.armed && x.landed == y.landed && x.sensors == y.sensors &&
                x.pictures == y.pictures)
        << "state " << i << " differs";
  }
  EXPECT_EQ(a.end_time, b.end_time);
}

TEST(Adapter, SimIsRegisteredUnderItsName) {
  mid::AdapterRegistry registry;
  register_adapter(registry);
  EXPECT_EQ(registry.names(), std::vector<std::string>{"sim"});
  mid::EventLoop loop;
  fleet::DroneSettings s = test::settings("Scout7");
  s.home = {1, 2, 0};
  mid::CreateResult r = registry.create(s.adapter, s, fleet::generic_multirotor("Quad"), loop);
  ASSERT_EQ(r.status, mid::CreateStatus::success) << r.message;
  EXPECT_EQ(r.drone->name(), "Scout7");
  EXPECT_DOUBLE_EQ(r.drone->state().x, 1.0);
  EXPECT_DOUBLE_EQ(r.drone->state().battery, 100.0);
  EXPECT_EQ(registry.create("mavlink", s, fleet::generic_multirotor("Quad"), loop).status,
            mid::CreateStatus::unknown_adapter);
}

}  // namespace
}  // namespace eamos::sim
