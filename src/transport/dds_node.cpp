#include "transport/dds_node.h"

#include <dds/dds.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "diag/file_read.h"
#include "diag/log.h"
#include "loopback_config.h"
#include "transport/wire_convert.h"

namespace eamos::transport {

namespace {

bool is_loopback(const std::string& interface) {
  return interface.empty() || interface == "127.0.0.1" || interface == "lo" || interface == "localhost";
}

bool looks_like_address(const std::string& s) {
  return !s.empty() && s.find_first_not_of("0123456789.:") == std::string::npos;
}

std::string retcode(dds_return_t rc) { return dds_strretcode(rc); }

/// Reliable, transient-local: what a reader needs even when it matched late.
/// `durable` 0: keep-last 1 (newest value wins, per instance); otherwise keep-all until
/// acknowledged, then the newest `durable` for late readers.
dds_qos_t* durable_qos(int durable, double lease_s) {
  dds_qos_t* q = dds_create_qos();
  // A write may block while readers catch up; never as long as the lease, or a busy drone
  // would look lost to the others.
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, static_cast<dds_duration_t>(lease_s / 4 * 1e9));
  dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
  // What a late reader gets is the durability service's history, not the writer's: its
  // default (keep-last 1) would hand a late DEX only the newest trigger. Cyclone keeps a
  // sample in the writer until every matched reader acknowledged it (keep-all history),
  // and after that only as long as it is among the durability service's newest `durable`.
  if (durable > 0) {
    dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
    dds_qset_durability_service(q, 0, DDS_HISTORY_KEEP_LAST, durable, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED,
                                DDS_LENGTH_UNLIMITED);
  } else {
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
    dds_qset_durability_service(q, 0, DDS_HISTORY_KEEP_LAST, 1, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED,
                                DDS_LENGTH_UNLIMITED);
  }
  return q;
}

/// The last net of a Cyclone callback, when even DdsNode::dropped failed: standard error,
/// after the first 20 only every 1000th, so a peer sending garbage cannot flood the log.
void log_dropped(const char* topic, const char* what) noexcept {
  static std::atomic<std::uint64_t> dropped{0};
  std::uint64_t n = ++dropped;
  if (n > 20 && n % 1000 != 0) return;
  try {
    diag::Logger{"transport", ""}.warning(std::string("dropped a DDS sample of ") + topic + " (" + std::to_string(n) +
                                          " so far): " + what);
  } catch (...) {  // Cyclone's thread must get control back whatever happens here
  }
}

/// Takes every sample the reader holds. Each is checked as it is converted (from_wire):
/// one that breaks a rule is dropped and reported to `node`, never handed on.
template <typename Wire, typename Sample, typename Claimed, typename Fn>
void take_all(dds_entity_t reader, const char* topic, DdsNode& node, Claimed&& claimed, Fn&& fn,
              std::function<void(std::uint64_t)> on_info = {}) {
  constexpr int kBatch = 64;
  void* samples[kBatch];
  dds_sample_info_t infos[kBatch];
  for (;;) {
    samples[0] = nullptr;
    int n = dds_take(reader, samples, infos, kBatch, kBatch);
    if (n <= 0) return;
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;  // dispose/unregister notices carry no sample
      // Per sample, so one bad sample neither loses the rest of the batch nor the loan.
      try {
        Sample s;
        std::string why;
        if (!from_wire(*static_cast<const Wire*>(samples[i]), node.wire_limits(), s, why)) {
          node.dropped(topic, why);
          continue;
        }
        // Who wrote it, not who it says it is: with DDS Security the writer's partition is
        // the identity that authenticated it.
        if (!node.sent_by(topic, claimed(s), node.sender_of(reader, infos[i].publication_handle))) continue;
        if (on_info) on_info(infos[i].publication_handle);
        fn(std::move(s));
      } catch (const std::exception& e) {
        node.dropped(topic, e.what());  // if this throws too, guarded() below logs it
      } catch (...) {
        node.dropped(topic, "an exception that is not a std::exception");
      }
    }
    dds_return_loan(reader, samples, n);
    if (n < kBatch) return;
  }
}

// Cyclone calls these from its own threads, through C: nothing may be thrown into it.
template <typename Take>
void guarded(const char* topic, Take&& take) noexcept {
  try {
    take();
  } catch (const std::exception& e) {
    log_dropped(topic, e.what());
  } catch (...) {
    log_dropped(topic, "an exception that is not a std::exception");
  }
}

void on_trigger(dds_entity_t reader, void* arg) noexcept {
  guarded("eamos_trigger", [&] { static_cast<DdsNode*>(arg)->take_triggers(reader); });
}
void on_telemetry(dds_entity_t reader, void* arg) noexcept {
  guarded("eamos_telemetry", [&] { static_cast<DdsNode*>(arg)->take_telemetry(reader); });
}
void on_lifecycle(dds_entity_t reader, void* arg) noexcept {
  guarded("eamos_lifecycle", [&] { static_cast<DdsNode*>(arg)->take_lifecycle(reader); });
}
void on_status(dds_entity_t reader, void* arg) noexcept {
  guarded("eamos_status", [&] { static_cast<DdsNode*>(arg)->take_status(reader); });
}
void on_trace(dds_entity_t reader, void* arg) noexcept {
  guarded("eamos_trace", [&] { static_cast<DdsNode*>(arg)->take_trace(reader); });
}
void on_liveliness(dds_entity_t, const dds_liveliness_changed_status_t s, void* arg) noexcept {
  if (s.alive_count_change < 0 || s.not_alive_count_change > 0)
    guarded("eamos_status (liveliness)",
            [&] { static_cast<DdsNode*>(arg)->liveliness_changed(s.last_publication_handle); });
}

/// The <Security> element: the three plugins Debian's libddsc0debian ships, and this
/// participant's credentials (file: URIs, absolute, as Cyclone resolves them itself).
bool security_config(const std::string& folder, std::string& xml, std::string& error) {
  std::error_code ec;
  std::string dir = std::filesystem::absolute(folder, ec).string();
  std::vector<std::string> uri;
  std::string missing;
  for (const char* f : kSecurityFiles) {
    std::string path = dir + "/" + f;
    if (!std::filesystem::is_regular_file(path, ec)) missing += (missing.empty() ? "" : ", ") + std::string(f);
    uri.push_back("file:" + path);
  }
  if (!missing.empty()) {
    error = "DDS Security credentials missing in " + dir + ": " + missing +
            "; compile the mission again (`eamos compile` writes them), or pass --insecure to fly without "
            "DDS Security";
    return false;
  }
  const std::string lib = EAMOS_DDS_SECURITY_PLUGIN_DIR;
  xml = "<CycloneDDS><Domain Id=\"any\"><Security>"
        "<Authentication><Library path=\"" + lib + "/libdds_security_auth.so\" initFunction=\"init_authentication\" "
        "finalizeFunction=\"finalize_authentication\"/>"
        "<IdentityCA>" + uri[0] + "</IdentityCA><IdentityCertificate>" + uri[1] + "</IdentityCertificate>"
        "<PrivateKey>" + uri[2] + "</PrivateKey></Authentication>"
        "<AccessControl><Library path=\"" + lib + "/libdds_security_ac.so\" initFunction=\"init_access_control\" "
        "finalizeFunction=\"finalize_access_control\"/>"
        "<PermissionsCA>" + uri[3] + "</PermissionsCA><Governance>" + uri[4] + "</Governance>"
        "<Permissions>" + uri[5] + "</Permissions></AccessControl>"
        "<Cryptographic><Library path=\"" + lib + "/libdds_security_crypto.so\" initFunction=\"init_crypto\" "
        "finalizeFunction=\"finalize_crypto\"/></Cryptographic>"
        "</Security></Domain></CycloneDDS>";
  return true;
}

bool base_config(const DdsOptions& options, std::string& xml, std::string& error) {
  if (!options.config_file.empty()) {
    // A Cyclone DDS configuration is a few kilobytes; more is not one.
    constexpr std::uint64_t kMaxConfigBytes = std::uint64_t{16} << 20;
    diag::FileRead r = diag::read_bounded_file(options.config_file, kMaxConfigBytes, xml, diag::Pipes::read);
    if (r.status != diag::FileRead::ok) {
      error = "cannot read DDS configuration '" + options.config_file + "': " + diag::describe(r, kMaxConfigBytes);
      return false;
    }
    return true;
  }
  if (is_loopback(options.interface)) {
    xml = kLoopbackConfig;
    return true;
  }
  std::string attr = looks_like_address(options.interface) ? "address" : "name";
  xml = "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface " + attr + "=\"" +
        options.interface + "\"/></Interfaces></General><Discovery><ParticipantIndex>auto</ParticipantIndex>"
        "<MaxAutoParticipantIndex>100</MaxAutoParticipantIndex></Discovery></Domain></CycloneDDS>";
  return true;
}

/// A writer whose readers have not acknowledged everything reminds them (a heartbeat, each
/// answered by every reader) every 100 ms by Cyclone's default. While dozens of participants
/// discover each other on one host, acknowledgements come late and these reminders were
/// most of the start's messages: every 500 ms, a 50-drone start on two cores took a third
/// of the CPU and no receive buffer overflowed (docs/performance.md). A new sample still
/// goes out at once; only reminders and resends after a loss wait longer, which would slow
/// a small fleet's start by about a second for nothing.
std::string large_fleet_config(int fleet) {
  if (fleet <= kQuickHeartbeatFleet) return "";
  return "<CycloneDDS><Domain Id=\"any\"><Internal><HeartbeatInterval min=\"50ms\" minsched=\"100ms\" "
         "max=\"8s\">500ms</HeartbeatInterval></Internal></Domain></CycloneDDS>";
}

}  // namespace

bool dds_config(const DdsOptions& options, std::string& xml, std::string& error, int fleet) {
  if (!base_config(options, xml, error)) return false;
  // Only ours: a user's file says what it means.
  if (options.config_file.empty() && is_loopback(options.interface)) xml += large_fleet_config(fleet);
  if (options.security_folder.empty()) return true;
  // Cyclone DDS merges configuration fragments given one after the other: the user's file
  // (or ours) stays as it is, the security settings come second.
  std::string security;
  if (!security_config(options.security_folder, security, error)) return false;
  xml += security;
  return true;
}

std::unique_ptr<DdsNode> DdsNode::open(const DdsOptions& options, DdsHandlers handlers, std::string& error) {
  std::unique_ptr<DdsNode> node(new DdsNode());
  node->handlers_ = std::move(handlers);
  if (!node->create(options, error)) return nullptr;
  return node;
}

bool DdsNode::create(const DdsOptions& options, std::string& error) {
  if (options.domain < 0 || options.domain > 230) {
    error = "DDS domain id " + std::to_string(options.domain) + " is out of range; use 0 to 230";
    return false;
  }
  if (!(options.lease_s > 0.0)) {
    error = "liveliness timeout must be positive";
    return false;
  }
  if (!dds_config(options, config_, error, handlers_.limits.drones)) return false;
  // A second node in one process (tests, benches) joins the domain the first one created.
  dds_entity_t domain = dds_create_domain(options.domain, config_.c_str());
  if (domain < 0 && domain != DDS_RETCODE_PRECONDITION_NOT_MET) {
    error = "cannot create DDS domain " + std::to_string(options.domain) + ": " + retcode(domain) +
            " (check --interface and --dds-config)";
    return false;
  }
  domain_ = domain > 0 ? domain : 0;
  participant_ = dds_create_participant(options.domain, nullptr, nullptr);
  if (participant_ < 0) {
    error = "cannot join DDS domain " + std::to_string(options.domain) + ": " + retcode(participant_) +
            (options.security_folder.empty() ? "" : " (DDS Security refused the credentials in " +
                                                        options.security_folder + "; see Cyclone's log above)");
    return false;
  }
  mission_hash_ = options.mission_hash;
  self_ = options.self;
  if (!create_endpoints(options, error)) return false;
  return true;
}

namespace {

/// A publisher or subscriber in `partitions` (none: the default partition).
dds_entity_t grouping(dds_entity_t participant, bool publisher, const std::vector<std::string>& partitions) {
  dds_qos_t* q = dds_create_qos();
  std::vector<const char*> names;
  for (const std::string& p : partitions) names.push_back(p.c_str());
  if (!names.empty()) dds_qset_partition(q, static_cast<uint32_t>(names.size()), names.data());
  dds_entity_t e = publisher ? dds_create_publisher(participant, q, nullptr) : dds_create_subscriber(participant, q, nullptr);
  dds_delete_qos(q);
  return e;
}

/// One topic of the wire and where its endpoints' handles go.
struct TopicSpec {
  const char* name;
  const dds_topic_descriptor_t* type;
  int durable;    ///< acknowledged samples kept for late readers (triggers, traces); 0: the newest value wins
  int* writer;    ///< 0 when this participant does not write the topic
  int* reader;    ///< 0 when it does not read it
  dds_on_data_available_fn on_data;
  bool write, read;
  bool liveliness;  ///< the status topic: manual liveliness, whose changes the reader hears
};

/// Where a topic's writer and reader go, and who hears the reader.
struct Endpoints {
  dds_entity_t participant, publisher, subscriber;
  void* node;  ///< the listeners' argument
};

/// Creates `spec`'s topic, its writer and its reader; false with `error` set when DDS refuses.
bool create_topic(const Endpoints& at, const TopicSpec& spec, const DdsOptions& options, std::string& error) {
  dds_qos_t* qos = durable_qos(spec.durable, options.lease_s);
  dds_entity_t topic = dds_create_topic(at.participant, spec.type, spec.name, qos, nullptr);
  if (topic < 0) {
    dds_delete_qos(qos);
    error = std::string("cannot create DDS topic ") + spec.name + ": " + retcode(topic);
    return false;
  }
  dds_qos_t* wqos = dds_create_qos();
  dds_copy_qos(wqos, qos);
  if (spec.liveliness) dds_qset_liveliness(wqos, DDS_LIVELINESS_MANUAL_BY_TOPIC, DDS_SECS(1) * options.lease_s);
  *spec.writer = spec.write ? dds_create_writer(at.publisher, topic, wqos, nullptr) : 0;
  dds_delete_qos(wqos);
  dds_listener_t* listener = dds_create_listener(at.node);
  dds_lset_data_available(listener, spec.on_data);
  if (spec.liveliness) dds_lset_liveliness_changed(listener, on_liveliness);
  dds_qset_ignorelocal(qos, DDS_IGNORELOCAL_PARTICIPANT);
  *spec.reader = spec.read ? dds_create_reader(at.subscriber, topic, qos, listener) : 0;
  dds_delete_listener(listener);
  dds_delete_qos(qos);
  if (*spec.writer < 0 || *spec.reader < 0) {
    error = std::string("cannot create DDS endpoints of ") + spec.name + ": " +
            retcode(*spec.writer < 0 ? *spec.writer : *spec.reader) +
            (options.security_folder.empty() ? "" : " (do the permissions in " + options.security_folder +
                                                        " belong to this drone and mission?)");
    return false;
  }
  return true;
}

}  // namespace

bool DdsNode::create_endpoints(const DdsOptions& options, std::string& error) {
  // Each participant writes in its own partition and reads the whole mission's: DDS
  // Security's permissions allow a drone to write only in its own (docs/security.md).
  std::vector<std::string> write_in, read_in;
  if (!mission_hash_.empty()) {
    write_in.push_back(partition_of(mission_hash_, options.self));
    read_in.push_back(partition_of(mission_hash_, kGroundParticipant));
    for (int d = 0; d < handlers_.limits.drones; ++d) read_in.push_back(partition_of(mission_hash_, d));
  }
  Endpoints at{participant_, grouping(participant_, true, write_in), grouping(participant_, false, read_in), this};
  if (at.publisher < 0 || at.subscriber < 0) {
    error = "cannot create the DDS publisher and subscriber: " +
            retcode(at.publisher < 0 ? at.publisher : at.subscriber);
    return false;
  }
  // The ground writes only lifecycle samples (its permissions allow nothing else).
  const bool drone = mission_hash_.empty() || options.self != kGroundParticipant;
  // Only the ground reads traces: a DEX does not take every other drone's events.
  const bool traces = handlers_.trace != nullptr;
  const int triggers = std::max(1, options.durable_triggers), trace = std::max(1, options.durable_trace);
  const TopicSpec specs[] = {
      {"eamos_trigger", &eamos_wire_Trigger_desc, triggers, &w_trigger_, &r_trigger_, on_trigger, drone, true, false},
      {"eamos_telemetry", &eamos_wire_Telemetry_desc, 0, &w_telemetry_, &r_telemetry_, on_telemetry, drone,
       true, false},
      {"eamos_lifecycle", &eamos_wire_Lifecycle_desc, 0, &w_lifecycle_, &r_lifecycle_, on_lifecycle, true, true,
       false},
      {"eamos_status", &eamos_wire_Status_desc, 0, &w_status_, &r_status_, on_status, drone, true, true},
      {"eamos_trace", &eamos_wire_TraceRecord_desc, trace, &w_trace_, &r_trace_, on_trace, drone, traces, false},
  };
  for (const TopicSpec& spec : specs)
    if (!create_topic(at, spec, options, error)) return false;
  return true;
}

DdsNode::~DdsNode() {
  if (!mission_hash_.empty())
    diag::Logger{"transport", self_ == kGroundParticipant ? std::string("ground") : "drone " + std::to_string(self_)}
        .debug("DDS samples: " + traffic());
  // Deleting the participant stops its listeners before anything they use goes away.
  if (participant_ > 0) dds_delete(participant_);
  if (domain_ > 0) dds_delete(domain_);
}

std::string DdsNode::traffic() const {
  static const char* const names[kTopics] = {"trigger", "telemetry", "lifecycle", "status", "trace"};
  std::string line;
  for (int t = 0; t < kTopics; ++t)
    line += std::string(t ? "; " : "") + names[t] + " " + std::to_string(written_[t]) + " written, " +
            std::to_string(received_[t]) + " received";
  return line;
}

bool DdsNode::write(const TriggerSample& s) {
  ++written_[kTrigger];
  eamos_wire_Trigger w = to_wire(s);
  return dds_write(w_trigger_, &w) == DDS_RETCODE_OK;
}

bool DdsNode::write(const TelemetrySample& s) {
  ++written_[kTelemetry];
  TelemetryOut out;
  to_wire(s, out);
  return dds_write(w_telemetry_, &out.c) == DDS_RETCODE_OK;
}

bool DdsNode::write(const LifecycleSample& s) {
  ++written_[kLifecycle];
  eamos_wire_Lifecycle w = to_wire(s);
  return dds_write(w_lifecycle_, &w) == DDS_RETCODE_OK;
}

bool DdsNode::write(const StatusSample& s) {
  ++written_[kStatus];
  eamos_wire_Status w = to_wire(s);
  return dds_write(w_status_, &w) == DDS_RETCODE_OK;
}

bool DdsNode::write(const TraceSample& s) {
  ++written_[kTrace];
  eamos_wire_TraceRecord w = to_wire(s);
  return dds_write(w_trace_, &w) == DDS_RETCODE_OK;
}

void DdsNode::assert_alive() {
  if (w_status_ > 0) dds_assert_liveliness(w_status_);
}

bool DdsNode::flush(double timeout_s) {
  // One deadline for all writers: a reader of a killed process stays matched until its
  // participant's lease ends (10 s) and never acknowledges, so each wait could run out.
  dds_time_t deadline = dds_time() + static_cast<dds_duration_t>(timeout_s * 1e9);
  bool ok = true;
  for (int w : {w_trace_, w_status_, w_lifecycle_, w_trigger_}) {
    if (w <= 0) continue;
    dds_duration_t left = std::max<dds_duration_t>(0, deadline - dds_time());
    ok = dds_wait_for_acks(w, left) == DDS_RETCODE_OK && ok;
  }
  return ok;
}

void DdsNode::take_triggers(int reader) {
  take_all<eamos_wire_Trigger, TriggerSample>(
      reader, "trigger", *this, [](const TriggerSample& s) { return s.message.from; }, [this](TriggerSample s) {
    count_received(kTrigger);
    if (handlers_.trigger) handlers_.trigger(std::move(s));
  });
}

void DdsNode::take_telemetry(int reader) {
  take_all<eamos_wire_Telemetry, TelemetrySample>(
      reader, "telemetry", *this, [](const TelemetrySample& s) { return s.telemetry.from; },
      [this](TelemetrySample s) {
    count_received(kTelemetry);
    if (handlers_.telemetry) handlers_.telemetry(std::move(s));
  });
}

void DdsNode::take_lifecycle(int reader) {
  take_all<eamos_wire_Lifecycle, LifecycleSample>(
      reader, "lifecycle", *this, [](const LifecycleSample& s) { return s.drone; }, [this](LifecycleSample s) {
    count_received(kLifecycle);
    if (handlers_.lifecycle) handlers_.lifecycle(std::move(s));
  });
}

void DdsNode::take_status(int reader) {
  std::uint64_t handle = 0;
  take_all<eamos_wire_Status, StatusSample>(
      reader, "status", *this, [](const StatusSample& s) { return s.drone; },
      [this, &handle](StatusSample s) {
        {
          std::lock_guard<std::mutex> lock(writers_mutex_);
          status_writers_[handle] = {s.mission_hash, s.drone, s.nonce};
        }
        count_received(kStatus);
        if (handlers_.status) handlers_.status(std::move(s));
      },
      [&handle](std::uint64_t h) { handle = h; });
}

void DdsNode::take_trace(int reader) {
  take_all<eamos_wire_TraceRecord, TraceSample>(
      reader, "trace", *this, [](const TraceSample& s) { return s.drone; }, [this](TraceSample s) {
    count_received(kTrace);
    if (handlers_.trace) handlers_.trace(std::move(s));
  });
}

void DdsNode::dropped(const char* topic, const std::string& why) {
  std::uint64_t n = ++dropped_;
  // A flood of bad samples must not flood the log: the first ten, then every thousandth.
  if (n > 10 && n % 1000 != 0) return;
  std::string line = std::string("dropped a ") + topic + " sample: " + why + " (" + std::to_string(n) +
                     " dropped so far)";
  if (handlers_.dropped) handlers_.dropped(line);
  else diag::Logger{"transport", ""}.warning(line);
}

int DdsNode::sender_of(int reader, std::uint64_t publication_handle) {
  if (mission_hash_.empty()) return kUnknownSender;
  {
    std::lock_guard<std::mutex> lock(senders_mutex_);
    auto it = senders_.find(publication_handle);
    if (it != senders_.end()) return it->second;
  }
  int sender = kUnknownSender;
  dds_builtintopic_endpoint_t* w = dds_get_matched_publication_data(reader, publication_handle);
  if (w) {
    uint32_t n = 0;
    char** names = nullptr;
    // One partition, of this mission: a writer in several could pose as several senders.
    if (dds_qget_partition(w->qos, &n, &names) && n == 1)
      sender = participant_of(mission_hash_, handlers_.limits.drones, names[0]);
    for (uint32_t i = 0; i < n; ++i) dds_free(names[i]);
    dds_free(names);
    dds_builtintopic_free_endpoint(w);
  }
  std::lock_guard<std::mutex> lock(senders_mutex_);
  senders_[publication_handle] = sender;
  return sender;
}

bool DdsNode::sent_by(const char* topic, int claimed, int sender) {
  if (mission_hash_.empty() || claimed == sender) return true;
  auto who = [](int d) {
    return d == kGroundParticipant ? std::string("the ground") : d == kUnknownSender ? std::string("no participant of this mission") : "drone " + std::to_string(d);
  };
  dropped(topic, "it says it is from " + who(claimed) + " but was written by " + who(sender) +
                     " (the partition its writer is in)");
  return false;
}

void DdsNode::liveliness_changed(std::uint64_t publication_handle) {
  Writer who;
  {
    std::lock_guard<std::mutex> lock(writers_mutex_);
    auto it = status_writers_.find(publication_handle);
    if (it == status_writers_.end()) return;  // a writer that never said which drone it is
    who = it->second;
  }
  if (handlers_.lost) handlers_.lost(who.mission_hash, who.drone, who.nonce);
}

}  // namespace eamos::transport
