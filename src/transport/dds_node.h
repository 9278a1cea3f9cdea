#pragma once
// One process's place on the DDS domain: a participant with the five eamos topics, a
// writer and a reader for each, and the QoS the delivery guarantees rest on:
//  - triggers: reliable, transient-local; the writer keeps every sample until each matched
//    reader has acknowledged it (keep-all history: none is lost), and of the acknowledged
//    ones the newest `durable_triggers` for a reader matched late (or again after a network
//    hiccup): memory bounded by the mission, not by its length;
//  - telemetry: reliable, transient-local, keep-last 1 per drone: newest value wins;
//  - lifecycle and status: reliable, transient-local, keep-last 1 per (mission, drone[,
//    kind]); the status writer offers MANUAL_BY_TOPIC liveliness with the lease, asserted
//    by its owner's event loop, so a hung DEX is as lost as a killed one;
//  - trace: as triggers, for the ground's merged trace, with `durable_trace` kept.
// Received samples are converted and handed to the handlers on a DDS thread: handlers
// must only post() to their event loop.
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "transport/partitions.h"
#include "transport/samples.h"

namespace eamos::transport {

inline constexpr int kDefaultDurableTriggers = 256;
/// About two seconds of a busy drone's trace events: what a ground that matched a DEX's
/// trace writer late still gets.
inline constexpr int kDefaultDurableTrace = 1024;

struct DdsOptions {
  int domain = 0;
  /// "" or "127.0.0.1": the shipped loopback configuration (config/cyclonedds-loopback.xml);
  /// otherwise a network interface name or address, with multicast discovery.
  std::string interface;
  std::string config_file;  ///< a Cyclone DDS XML file of the user's, used as is
  double lease_s = 2.0;     ///< status writer liveliness lease: how soon a lost drone is noticed
  /// The mission this participant belongs to and who it is in it (a drone index, or
  /// kGroundParticipant): the partition it writes in, and the mission's partitions it
  /// reads (partitions.h). "" (a node on its own, in tests): the default partition, and
  /// samples are not bound to their writers.
  std::string mission_hash;
  int self = kGroundParticipant;
  /// This participant's DDS Security credentials (written by `eamos compile`, see
  /// docs/security.md): identity_ca.pem, permissions_ca.pem, governance.p7s, identity.pem,
  /// identity_key.pem and permissions.p7s. "": no DDS Security (`--insecure`).
  std::string security_folder;
  /// Acknowledged samples the trigger and trace writers keep for readers that match late
  /// (durability service history depth). The DEX sizes the first from its mission
  /// (launch/dex_process.cpp).
  int durable_triggers = kDefaultDurableTriggers;
  int durable_trace = kDefaultDurableTrace;
};

/// Wall seconds after which Cyclone DDS 0.10 gives up a DDS Security handshake that has not
/// completed (AUTHENTICATION_TIMEOUT in its ddsi_handshake.c). Debian 12's build (0.10.2)
/// can crash at that moment: the handler of this timeout races with the handshake's other
/// timers on one heap (eclipse-cyclonedds/cyclonedds#1548, fixed in 11.0). No eamos process
/// keeps a handshake pending that long: a DEX not ready by kSecureUnreadyLimitS leaves the
/// domain (launch/dex_process.h), and the ground's start barrier ends before it.
inline constexpr double kHandshakeGiveUpS = 100.0;

/// The files of a security folder, in the order the Cyclone DDS configuration names them.
inline constexpr const char* kSecurityFiles[] = {"identity_ca.pem",   "identity.pem",   "identity_key.pem",
                                                 "permissions_ca.pem", "governance.p7s", "permissions.p7s"};

struct DdsHandlers {
  std::function<void(TriggerSample)> trigger;
  std::function<void(TelemetrySample)> telemetry;
  std::function<void(LifecycleSample)> lifecycle;
  std::function<void(StatusSample)> status;
  std::function<void(TraceSample)> trace;
  /// A status writer lost its liveliness (lease expired, or its process went away):
  /// the mission, drone and process (nonce) it belonged to.
  std::function<void(const std::string& mission_hash, int drone, std::uint64_t nonce)> lost;
  /// A received sample broke a rule of from_wire and was dropped: one log line saying
  /// which topic and why (rate-limited). Unset: the line goes to the log (diag/log.h).
  std::function<void(const std::string& line)> dropped;
  /// What received samples are checked against: the mission's drone count.
  WireLimits limits;
};

class DdsNode {
 public:
  /// Joins the domain; nullptr with `error` set when Cyclone DDS refuses (bad config file,
  /// unknown interface, domain id out of range).
  static std::unique_ptr<DdsNode> open(const DdsOptions& options, DdsHandlers handlers, std::string& error);
  ~DdsNode();
  DdsNode(const DdsNode&) = delete;
  DdsNode& operator=(const DdsNode&) = delete;

  // Writers; false when DDS refused the write (logged by the caller).
  bool write(const TriggerSample& s);
  bool write(const TelemetrySample& s);
  bool write(const LifecycleSample& s);
  bool write(const StatusSample& s);
  bool write(const TraceSample& s);
  /// Tells the others this process is alive (MANUAL_BY_TOPIC liveliness of the status writer).
  void assert_alive();
  /// Waits until every reader has acknowledged what was written (before a clean exit).
  bool flush(double timeout_s);
  /// The configuration XML in use (for logs and tests).
  const std::string& config() const { return config_; }

  // Called from DDS listener threads with the reader that has data: possibly while
  // dds_create_reader is still running (historical data of a transient-local writer in
  // this process), before the reader's handle is stored.
  void take_triggers(int reader);
  void take_telemetry(int reader);
  void take_lifecycle(int reader);
  void take_status(int reader);
  void take_trace(int reader);
  void liveliness_changed(std::uint64_t publication_handle);
  /// Whose partition the writer `publication_handle` of `reader` writes in: a drone index,
  /// kGroundParticipant or kUnknownSender. With DDS Security, the identity that
  /// authenticated it (its permissions allow no other partition).
  int sender_of(int reader, std::uint64_t publication_handle);
  /// False (and the sample dropped, logged) when a sample claiming to come from `claimed`
  /// was written by someone else. Always true for a node without a mission hash.
  bool sent_by(const char* topic, int claimed, int sender);
  /// Checks for received samples, and where a dropped one is reported.
  const WireLimits& wire_limits() const { return handlers_.limits; }
  void dropped(const char* topic, const std::string& why);
  /// Samples dropped so far (for tests).
  std::uint64_t dropped_count() const { return dropped_; }
  /// Samples written and received (accepted) so far per topic, one line: what a process
  /// cost the others, for `--log-level=debug` and the measurements of docs/performance.md.
  std::string traffic() const;
  enum Topic { kTrigger, kTelemetry, kLifecycle, kStatus, kTrace, kTopics };
  void count_received(Topic t) { ++received_[t]; }

 private:
  DdsNode() = default;
  bool create(const DdsOptions& options, std::string& error);
  bool create_endpoints(const DdsOptions& options, std::string& error);

  DdsHandlers handlers_;
  std::string config_;
  int domain_ = 0;
  int participant_ = 0;
  int w_trigger_ = 0, w_telemetry_ = 0, w_lifecycle_ = 0, w_status_ = 0, w_trace_ = 0;
  int r_trigger_ = 0, r_telemetry_ = 0, r_lifecycle_ = 0, r_status_ = 0, r_trace_ = 0;
  struct Writer {
    std::string mission_hash;
    int drone = 0;
    std::uint64_t nonce = 0;
  };
  std::mutex writers_mutex_;  ///< per status writer: whose it is, for liveliness reports
  std::map<std::uint64_t, Writer> status_writers_;
  std::string mission_hash_;  ///< "" = samples are not bound to their writers
  int self_ = kGroundParticipant;
  std::mutex senders_mutex_;  ///< per remote writer: whose partition it writes in
  std::map<std::uint64_t, int> senders_;
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> written_[kTopics] = {}, received_[kTopics] = {};
};

/// Notes: a second node in one process joins the domain the first created, and the first
/// one's destruction ends the domain for both: tests destroy them in reverse order.

/// Fleets up to this many drones keep Cyclone DDS's heartbeat of 100 ms on loopback; larger
/// ones send it every 500 ms (dds_node.cpp, large_fleet_config).
inline constexpr int kQuickHeartbeatFleet = 20;

/// The Cyclone DDS XML for `options` (loopback, an interface, or the user's file), with
/// the DDS Security plugins and `options.security_folder`'s credentials when it is set.
/// `fleet`: the mission's drones (0: not known), which sets the loopback heartbeat.
bool dds_config(const DdsOptions& options, std::string& xml, std::string& error, int fleet = 0);

}  // namespace eamos::transport
