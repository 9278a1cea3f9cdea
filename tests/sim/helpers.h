#pragma once
// A simulated drone on a virtual clock, and a way to run one action to its end.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "mid/event_loop.h"
#include "sim/sim_drone.h"

namespace eamos::sim::test {

/// What became of one started action.
struct Result {
  mid::ActionId id = mid::kNoAction;
  bool ended = false;
  mid::ActionEnd end;
  double t = -1;  ///< mission time its end was reported
};

inline fleet::DroneSettings settings(const std::string& name = "Drone1") {
  fleet::DroneSettings s;
  s.name = name;
  s.type = "Quad";
  return s;
}

class SimTest : public ::testing::Test {
 protected:
  mid::EventLoop loop;
  fleet::DroneSettings config = settings();
  fleet::DroneType type = fleet::generic_multirotor("Quad");
  std::unique_ptr<SimDrone> drone;

  SimDrone& make() {
    drone = std::make_unique<SimDrone>(config, type, loop);
    return *drone;
  }
  SimDrone& d() { return drone ? *drone : make(); }

  /// Starts an action; the result fills in when its end is reported.
  std::shared_ptr<Result> start(const std::string& name, std::vector<double> args = {}) {
    auto r = std::make_shared<Result>();
    r->id = d().start({name, std::move(args)}, [this, r](const mid::ActionEnd& e) {
      r->ended = true;
      r->end = e;
      r->t = loop.now();
    });
    return r;
  }

  /// Starts an action and runs the loop until it ended (at most `limit` mission seconds).
  Result run(const std::string& name, std::vector<double> args = {}, double limit = 3600) {
    auto r = start(name, std::move(args));
    run_until_ended(*r, limit);
    return *r;
  }

  void run_until_ended(const Result& r, double limit = 3600) {
    double until = loop.now() + limit;
    while (!r.ended && loop.now() < until) {
      if (loop.size() == 0) break;  // nothing left that could end it
      loop.run_until(std::min(until, loop.now() + 0.05));
    }
    ASSERT_TRUE(r.ended) << "action did not end within " << limit << " s";
  }

  /// Armed and hovering at `alt` metres.
  void airborne(double alt = 10) {
    ASSERT_EQ(run("Arm").end.outcome, mid::Outcome::succeeded);
    Result t = run("Takeoff", {alt});
    ASSERT_EQ(t.end.outcome, mid::Outcome::succeeded) << t.end.reason;
  }
};

}  // namespace eamos::sim::test
