// How an abandoned mission ends (dex/failsafe.h), shared by the in-process runner and each
// DEX process: every drone commanded before any failsafe is recorded, then a wait until
// each failsafe is over. Simulated drones on virtual time.
#include <gtest/gtest.h>

#include "dex/failsafe.h"
#include "flight.h"

namespace eamos {
namespace {

/// Three drones of one mission with engines that never start: A and B flown to 5 m, C on
/// the ground, disarmed.
struct Fleet {
  explicit Fleet(fleet::Failsafe failsafe = fleet::Failsafe::land) {
    missions = test::missions_of("var A Quad\nvar B Quad\nvar C Quad\n"
                                 "func INIT() { A.Arm(); B.Arm(); C.Arm() }\n");
    sim::register_adapter(adapters);
    for (dex::Mission& m : missions) {
      m.settings.failsafe = failsafe;
      drones.push_back(std::move(adapters.create(m.settings.adapter, m.settings, m.type, loop).drone));
      engines.push_back(std::make_unique<dex::Engine>(m, *drones.back(), loop, dex::EngineHooks{}));
    }
    for (int d = 0; d < 2; ++d) {
      drones[d]->start({"Arm", {}}, [this, d](const mid::ActionEnd&) {
        drones[d]->start({"Takeoff", {5}}, [](const mid::ActionEnd&) {});
      });
    }
    loop.run_until(30);
  }
  std::vector<dex::FailsafeDrone> all() {
    std::vector<dex::FailsafeDrone> out;
    for (std::size_t d = 0; d < drones.size(); ++d)
      out.push_back({engines[d].get(), drones[d].get(), &missions[d].settings});
    return out;
  }

  std::vector<dex::Mission> missions;
  mid::EventLoop loop;
  mid::AdapterRegistry adapters;
  std::vector<std::unique_ptr<mid::Drone>> drones;
  std::vector<std::unique_ptr<dex::Engine>> engines;
};

TEST(AbandonedMission, AnAbandonedFleetIsCommandedWholeBeforeAnyFailsafeIsRecorded) {
  Fleet f;
  ASSERT_EQ(f.drones.size(), 3u);
  ASSERT_NEAR(f.drones[1]->state().z, 5.0, 0.1);
  dex::MemoryTrace trace;
  bool between_ran = false;
  dex::abandon_drones(f.all(), f.loop.now(), "a test", &trace, [&] {
    between_ran = true;
    EXPECT_TRUE(trace.events.empty());  // nothing recorded before every drone was commanded
    EXPECT_EQ(f.drones[0]->state().mode.rfind("failsafe", 0), 0u) << f.drones[0]->state().mode;
    EXPECT_EQ(f.drones[1]->state().mode.rfind("failsafe", 0), 0u) << f.drones[1]->state().mode;
  });
  EXPECT_TRUE(between_ran);
  // C was down and disarmed: it needed no failsafe, and none is recorded for it.
  ASSERT_EQ(trace.events.size(), 2u);
  EXPECT_EQ(trace.events[0].drone, "A");
  EXPECT_EQ(trace.events[1].drone, "B");
  EXPECT_EQ(trace.events[0].event, "failsafe");
  EXPECT_EQ(trace.events[0].name, "land");
  EXPECT_EQ(trace.events[0].reason, "a test");
}

TEST(AbandonedMission, TheWaitEndsOnceTheLastDroneIsDownAndDisarmed) {
  Fleet f;
  dex::abandon_drones(f.all(), f.loop.now(), "a test", nullptr);
  double abandoned_at = f.loop.now();
  int over = 0;
  dex::FailsafeWait wait(f.loop, f.all(), 0.1, [&] {
    ++over;
    for (const auto& d : f.drones) EXPECT_TRUE(dex::down_and_disarmed(d->state())) << d->name();
    f.loop.stop();
  });
  wait.start();
  f.loop.run_until(abandoned_at + dex::kFailsafeWaitLimitS);
  EXPECT_EQ(over, 1);
  EXPECT_GT(f.loop.now(), abandoned_at + 1.0);  // landing from 5 m takes its time
  EXPECT_LT(f.loop.now(), abandoned_at + 60.0);
}

TEST(AbandonedMission, HoveringDronesNeedNoWait) {
  Fleet f(fleet::Failsafe::hover);
  dex::abandon_drones(f.all(), f.loop.now(), "a test", nullptr);
  double abandoned_at = f.loop.now();
  int over = 0;
  dex::FailsafeWait wait(f.loop, f.all(), 0.1, [&] {
    ++over;
    f.loop.stop();
  });
  wait.start();
  f.loop.run_until(abandoned_at + dex::kFailsafeWaitLimitS);
  EXPECT_EQ(over, 1);
  EXPECT_EQ(f.loop.now(), abandoned_at);  // the first look, after what was already queued
  EXPECT_FALSE(f.drones[0]->state().landed);
}

TEST(AbandonedMission, AWaitDestroyedBeforeTheEndLooksNoMore) {
  Fleet f;
  dex::abandon_drones(f.all(), f.loop.now(), "a test", nullptr);
  int over = 0;
  {
    dex::FailsafeWait wait(f.loop, f.all(), 0.1, [&] { ++over; });
    wait.start();
    f.loop.run_until(f.loop.now() + 0.5);  // A and B are still coming down
  }
  f.loop.run_until(f.loop.now() + 120);
  EXPECT_EQ(over, 0);
  EXPECT_TRUE(dex::down_and_disarmed(f.drones[0]->state()));
}

// A vehicle as an autopilot reports it, state set by the test: PX4 SITL disarmed vehicles on
// the ground during a takeoff and went on reporting them not landed (its land detector).
class ReportedDrone final : public mid::Drone {
 public:
  const std::string& name() const override { return name_; }
  mid::ActionId start(const mid::ActionRequest&, mid::EndCallback) override { return 1; }
  bool cancel(mid::ActionId) override { return false; }
  mid::DroneState state() const override { return state_; }
  mid::SubscriptionId subscribe(mid::StateCallback) override { return 1; }
  void unsubscribe(mid::SubscriptionId) override {}
  void failsafe(fleet::Failsafe what) override { failsafes.push_back(what); }

  std::string name_ = "Drone1";
  mid::DroneState state_;
  std::vector<fleet::Failsafe> failsafes;  ///< every failsafe commanded
};

TEST(AbandonedMission, ADisarmedDroneItsAutopilotCallsNotLandedEndsTheWaitAfterItsSettleTime) {
  Fleet f;
  ReportedDrone reported;
  reported.state_.armed = true;
  reported.state_.landed = false;
  std::vector<dex::FailsafeDrone> drones = {{f.engines[2].get(), &reported, &f.missions[2].settings}};
  double abandoned_at = f.loop.now(), over_at = -1;
  dex::FailsafeWait wait(f.loop, drones, 0.1, [&] {
    over_at = f.loop.now();
    f.loop.stop();
  });
  wait.start();
  f.loop.run_until(abandoned_at + 20.0);  // armed in the air: its failsafe still flies
  EXPECT_LT(over_at, 0);
  reported.state_.armed = false;  // disarmed, not landed by its autopilot's word
  f.loop.run_until(abandoned_at + 22.0);
  reported.state_.armed = true;  // a disarm that does not last does not count
  f.loop.run_until(abandoned_at + 30.0);
  EXPECT_LT(over_at, 0);
  reported.state_.armed = false;
  double disarmed_at = f.loop.now();
  f.loop.run_until(abandoned_at + dex::kFailsafeWaitLimitS);
  EXPECT_GE(over_at, disarmed_at + dex::kDisarmedSettleS);
  EXPECT_LT(over_at, disarmed_at + dex::kDisarmedSettleS + 0.5);
  EXPECT_FALSE(reported.state().landed);
}

// A drone down and disarmed when the mission was abandoned needs no failsafe; armed later
// (an ARM sent for the mission that took effect late), it gets one then, recorded.
TEST(AbandonedMission, ADroneArmedAfterTheAbandonmentGetsItsFailsafeThen) {
  Fleet f;
  ReportedDrone late;
  late.name_ = "C";
  std::vector<dex::FailsafeDrone> drones = f.all();
  drones[2].drone = &late;  // C: on the ground, disarmed
  dex::MemoryTrace trace;
  dex::abandon_drones(drones, f.loop.now(), "a test", &trace);
  ASSERT_EQ(trace.events.size(), 2u);  // A and B, flying
  EXPECT_TRUE(late.failsafes.empty());
  double abandoned_at = f.loop.now();
  int over = 0;
  dex::FailsafeWait wait(f.loop, drones, 0.1, [&] {
    ++over;
    f.loop.stop();
  }, &trace);
  wait.start();
  f.loop.run_until(abandoned_at + 0.5);  // A and B still coming down
  EXPECT_TRUE(late.failsafes.empty());
  late.state_.armed = true;
  f.loop.run_until(abandoned_at + 0.65);
  ASSERT_EQ(late.failsafes.size(), 1u);
  EXPECT_EQ(late.failsafes[0], fleet::Failsafe::land);
  ASSERT_EQ(trace.events.size(), 3u);
  EXPECT_EQ(trace.events[2].event, "failsafe");
  EXPECT_EQ(trace.events[2].drone, "C");
  EXPECT_EQ(trace.events[2].reason, "armed after the mission was abandoned");
  late.state_.armed = false;  // its failsafe disarmed it where it stood
  f.loop.run_until(abandoned_at + dex::kFailsafeWaitLimitS);
  EXPECT_EQ(over, 1);
  EXPECT_EQ(late.failsafes.size(), 1u) << "commanded once";
}

TEST(AbandonedMission, TheRuleForAFailsafeThatIsOver) {
  mid::DroneState s;
  s.armed = false;
  s.landed = true;
  EXPECT_TRUE(dex::failsafe_over(s, fleet::Failsafe::land, 0.0, 0.0)) << "down and disarmed";
  s.landed = false;
  EXPECT_FALSE(dex::failsafe_over(s, fleet::Failsafe::land, 0.0, 0.0));
  EXPECT_FALSE(dex::failsafe_over(s, fleet::Failsafe::land, 100.0, dex::kDisarmedSettleS - 0.1));
  EXPECT_TRUE(dex::failsafe_over(s, fleet::Failsafe::land, 100.0, dex::kDisarmedSettleS)) << "disarmed for its settle time";
  s.armed = true;
  EXPECT_FALSE(dex::failsafe_over(s, fleet::Failsafe::land, 100.0, 0.0)) << "armed in the air, landing";
  EXPECT_TRUE(dex::failsafe_over(s, fleet::Failsafe::hover, 0.0, 0.0)) << "hovering as told";
  s.landed = true;
  EXPECT_FALSE(dex::failsafe_over(s, fleet::Failsafe::hover, 0.0, 0.0)) << "armed on the ground: its disarm is to come";
  EXPECT_TRUE(dex::failsafe_over(s, fleet::Failsafe::land, dex::kFailsafeWaitLimitS, 0.0)) << "waited its limit";
  s.link_lost = true;
  EXPECT_TRUE(dex::failsafe_over(s, fleet::Failsafe::land, 0.0, 0.0)) << "its link lost";
}

}  // namespace
}  // namespace eamos
