#pragma once
// Action timeouts. A real vehicle can stall (a gust, a rejected setpoint, a lost link), and a
// mission must notice instead of waiting forever, so every action has a deadline:
//
//   timeout = expected × kTimeoutMargin + kTimeoutSlack_s
//
// where `expected` is the time the action takes at the platform's limits: horizontal
// distance / max_speed plus vertical distance / max_climb (or max_descent) for Takeoff,
// Land, FlyTo, FlyBy*, ReturnHome; the duration for Hover(s); 0 for payload and system
// actions. The slack covers accelerating and braking and the autopilot's reaction time. A
// fleet file's `timeouts:` (DroneSettings::timeouts_s) replaces the derived value per action
// name. Hover() and Orbit() run until preempted or cancelled, so they have no timeout at all.
//
// A derived deadline can come while the vehicle still closes on its goal, only slower than
// its limits say: a gust, a loaded SITL, PX4 SIH creeping the last half metre. An adapter that
// knows how far the vehicle still has to go (AdapterDrone::distance_left) then gives it
// kClosingWindow_s more each time it came at least kClosingMin_m nearer in the last window,
// at most the deadline again: a vehicle that stalls fails when its deadline comes, one that
// crawls fails at twice it. A deadline the fleet file sets never moves on.
#include "fleet/fleet.h"
#include "mid/drone_api.h"

namespace eamos::mid {

inline constexpr double kTimeoutMargin = 1.5;
inline constexpr double kTimeoutSlack_s = 10.0;
inline constexpr double kClosingWindow_s = 3.0;
inline constexpr double kClosingMin_m = 0.1;

/// Seconds `request` takes at the drone's limits from `position`; infinity when it has no
/// end of its own (Hover(), Orbit()).
double expected_duration(const ActionRequest& request, fleet::Vec3 position,
                         const fleet::DroneSettings& drone);

/// The deadline of `request` in seconds after its start; infinity for no deadline.
double action_timeout(const ActionRequest& request, fleet::Vec3 position,
                      const fleet::DroneSettings& drone);

/// True for the actions that run until preempted or cancelled: Hover() and Orbit(…).
bool is_endless(const ActionRequest& request);

}  // namespace eamos::mid
