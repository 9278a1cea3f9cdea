// `eamos sim-vehicle`: one PX4-like (or ArduPilot-like) MAVLink vehicle on the built-in simulator, in real time,
// until interrupted or its --duration ends. Stands in for PX4 SITL in tests and demos.
#include <csignal>
#include <iostream>

#include "cli/arguments.h"
#include "cli/commands.h"
#include "diag/printable.h"
#include "fleet/link_url.h"
#include "launch/stop_signals.h"
#include "mid/event_loop.h"
#include "sim_vehicle/sim_vehicle.h"

namespace eamos::cli {

namespace {
volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }
}  // namespace

int cmd_sim_vehicle(const SimVehicleCommandOptions& o) {
  std::string url = o.connection;
  if (url.empty()) url = "udpout://127.0.0.1:" + std::to_string(o.udp_port);
  fleet::EndpointResult endpoint = fleet::parse_link_url(url);
  if (!endpoint.endpoint) {
    std::cerr << error_prefix() << "connection '" << diag::printable(url, 120) << "': " << endpoint.error << "\n";
    return 1;
  }
  mid::EventLoop loop({mid::ClockMode::real_time, o.speed});
  sim_vehicle::VehicleOptions options;
  options.sysid = static_cast<uint8_t>(o.sysid);
  options.battery_percent = o.battery;
  options.east_m = o.east;
  options.north_m = o.north;
  options.dialect = o.autopilot == "ardupilot" ? &sim_vehicle::ardupilot_dialect() : &sim_vehicle::px4_dialect();
  sim_vehicle::SimVehicle vehicle(loop, options);
  if (std::string error = vehicle.open(*endpoint.endpoint); !error.empty()) {
    std::cerr << error_prefix() << "" << error << "\n";
    return 1;
  }
  if (!o.ground_station.empty()) {
    fleet::EndpointResult gcs = fleet::parse_link_url(o.ground_station);
    std::string error = gcs.endpoint ? vehicle.open_ground_station(*gcs.endpoint) : "'" + diag::printable(o.ground_station, 120) + "': " + gcs.error;
    if (!error.empty()) {
      std::cerr << error_prefix() << "--gcs " << error << "\n";
      return 1;
    }
  }
  // The local port: where a second ground station (a test playing a pilot) reaches the vehicle.
  std::cout << "sim-vehicle: system " << o.sysid << " (" << options.dialect->name << "-like) on " << url
            << ", receiving on port " << vehicle.local_port() << std::endl;
  launch::on_stop_signals(on_signal);
  // Short slices, so a signal is noticed within a quarter of a (mission) second.
  while (!g_stop && (o.duration <= 0 || loop.now() < o.duration))
    loop.run_until(o.duration > 0 ? std::min(o.duration, loop.now() + 0.25) : loop.now() + 0.25);
  return 0;
}

}  // namespace eamos::cli
