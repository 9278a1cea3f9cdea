#pragma once
// How late the messages between drones arrived in a distributed run: the ground's summary
// and console report the maximum and the 99th percentile, and name every message later than
// the warning bound (docs/trace.md, "Messages between drones"; docs/faults.md).
#include <cstddef>
#include <string>
#include <vector>

#include "dex/trace.h"

namespace eamos::dex {

/// The default of `--trigger-latency-warn`, mission seconds: far above what a working
/// network gives (milliseconds), well below what changes a mission's course (a drone at
/// 5 m/s moves 2.5 m meanwhile).
inline constexpr double kDefaultLatencyWarnS = 0.5;

/// A trigger or cancel that arrived later than the bound.
struct LateMessage {
  std::string kind;  ///< trigger | cancel
  std::string from;  ///< sender drone
  std::string to;    ///< receiver drone
  int node = -1;     ///< MEG id of the node it carries
  double sent = 0.0;
  double latency = 0.0;  ///< mission seconds: received - sent
};

struct MessageLatency {
  std::size_t count = 0;  ///< triggers and cancels that crossed between drones
  double max_s = 0.0;
  double p99_s = 0.0;     ///< nearest rank: 99 % of the messages were at most this late
  double warn_s = kDefaultLatencyWarnS;
  std::vector<LateMessage> late;  ///< the messages later than warn_s, in trace order
};

/// Latency of a message event (`received` - `sent`, mission seconds).
inline double latency_of(const TraceEvent& e) { return e.t - e.sent; }

/// True for the events the bound is about: a trigger or cancel from one drone to another
/// (FINISHED and ABORT are stamped with the ground's estimate of when it heard them).
bool is_drone_message(const TraceEvent& e);

/// Name of drone `index` in `fleet`, "?" outside it.
std::string drone_name_of(const std::vector<std::string>& fleet, int index);

/// The latency figures of every trigger and cancel in `events`.
MessageLatency message_latency(const std::vector<TraceEvent>& events, const std::vector<std::string>& fleet,
                               double warn_s);

/// "trigger from Drone1 to Drone2 (node 23) was received 1.250 mission s after it was sent at 3.100 s"
std::string describe_late(const LateMessage& m);

/// A late message from its trace event.
LateMessage late_message(const TraceEvent& e, const std::vector<std::string>& fleet);

}  // namespace eamos::dex
