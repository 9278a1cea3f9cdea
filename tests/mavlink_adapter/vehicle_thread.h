#pragma once
// A simulated MAVLink vehicle on its own thread and real-time loop, as a separate process
// would be, for the adapter's loopback tests. It sends to udpout://127.0.0.1:PORT.
#include <atomic>
#include <future>
#include <stdexcept>
#include <thread>

#include "fleet/link_url.h"
#include "mid/event_loop.h"
#include "sim_vehicle/sim_vehicle.h"

namespace eamos::test {

class VehicleThread {
 public:
  VehicleThread(int port, uint8_t sysid, double speed,
                const sim_vehicle::Dialect& dialect = sim_vehicle::px4_dialect(),
                double battery_percent = 100.0, bool camera_confirms = true)
      : VehicleThread(port, speed, options(dialect, sysid, battery_percent, camera_confirms)) {}
  VehicleThread(int port, double speed, const sim_vehicle::VehicleOptions& options)
      : loop_({mid::ClockMode::real_time, speed}), vehicle_(loop_, options) {
    std::string url = "udpout://127.0.0.1:" + std::to_string(port);
    if (std::string e = vehicle_.open(*eamos::fleet::parse_link_url(url).endpoint); !e.empty())
      throw std::runtime_error(e);
    thread_ = std::thread([this] {
      while (!stop_) loop_.run_until(loop_.now() + 1.0);
    });
  }
  ~VehicleThread() { halt(); }

  static sim_vehicle::VehicleOptions options(const sim_vehicle::Dialect& dialect, uint8_t sysid,
                                             double battery_percent, bool camera_confirms) {
    sim_vehicle::VehicleOptions o{&dialect, sysid, battery_percent};
    o.camera_confirms = camera_confirms;
    return o;
  }

  /// The vehicle's mode; only after halt(), when its loop no longer runs.
  sim_vehicle::Mode mode() const { return vehicle_.mode(); }
  /// Where the vehicle receives: a test can play a second ground station (a pilot's switch).
  uint16_t port() const { return vehicle_.local_port(); }

  /// Runs `f(vehicle)` on the running vehicle's loop and returns what it returns: how a test
  /// looks at the vehicle without racing its thread.
  template <typename F>
  auto inspect(F f) {
    std::promise<decltype(f(vehicle_))> result;
    auto future = result.get_future();
    loop_.post([&] { result.set_value(f(vehicle_)); });
    return future.get();
  }

  /// Stops the vehicle's loop, as if the vehicle vanished: no heartbeats any more.
  void halt() {
    if (!thread_.joinable()) return;
    stop_ = true;
    loop_.post([this] { loop_.stop(); });
    thread_.join();
  }

 private:
  mid::EventLoop loop_;
  sim_vehicle::SimVehicle vehicle_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace eamos::test
