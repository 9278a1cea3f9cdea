#pragma once
// The adapter's side of a loopback flight: a registry with the mavlink adapter, one drone
// connected to a simulated vehicle (vehicle_thread.h), and a way to fly one action.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mavlink_adapter/adapter.h"
#include "vehicle_thread.h"

namespace eamos::test {

/// Real time sped up 4×: every test flies a few mission seconds.
constexpr double kSpeed = 4.0;

struct Flight {
  mid::EventLoop loop{{mid::ClockMode::real_time, kSpeed}};
  mid::AdapterRegistry registry;
  std::unique_ptr<mid::Drone> drone;
  mid::CreateResult created;

  /// `edit` changes the drone's fleet settings before it is made (signing, say).
  explicit Flight(int port, mavlink_adapter::MavlinkOptions options = {},
                  const std::function<void(fleet::DroneSettings&)>& edit = {}) {
    options.real_time = true;
    options.speed = kSpeed;
    mavlink_adapter::register_adapter(registry, options);
    fleet::DroneSettings s;
    s.name = "Drone1";
    s.adapter = "mavlink";
    s.connection = "udp://127.0.0.1:" + std::to_string(port);
    s.sysid = 1;
    if (edit) edit(s);
    created = registry.create("mavlink", s, fleet::generic_multirotor("Quad"), loop);
    drone = std::move(created.drone);
  }

  /// Starts an action and runs the loop until it ends (at most `max_s` mission seconds).
  mid::ActionEnd fly(const std::string& name, std::vector<double> args = {}, double max_s = 60) {
    // A drone that never connected (its port taken, say) fails the test by its assertion,
    // not by a call through a null pointer.
    if (!drone) return mid::ActionEnd{mid::Outcome::failed, "test: no drone: " + created.message};
    std::optional<mid::ActionEnd> end;
    drone->start({name, std::move(args)}, [&](const mid::ActionEnd& e) {
      end = e;
      loop.stop();
    });
    loop.run_until(loop.now() + max_s);
    return end.value_or(mid::ActionEnd{mid::Outcome::failed, "test: no end within the limit"});
  }
};

}  // namespace eamos::test
