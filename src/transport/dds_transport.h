#pragma once
// The DEX's Transport (dex/bridge.h) over DDS: OutBridge writes triggers and telemetry as
// samples tagged with the mission hash and run id; it counts what it sent, which the
// status uses to tell when nothing is in flight. Every sample has its own sequence number
// (receivers drop duplicates by it); only `ended` triggers are counted as sent: a cancel
// goes to every drone, also those whose mission does not hold the flipped condition, so a
// receiver cannot tell a real one it has no use for from a forged one, and a cancel only
// ever stops work, never starts any, so the lead need not wait for one in flight.
#include <cstdint>
#include <functional>

#include "dex/bridge.h"
#include "transport/dds_node.h"

namespace eamos::transport {

class DdsTransport : public dex::Transport {
 public:
  DdsTransport(DdsNode& node, std::uint64_t run_id) : node_(node), run_id_(run_id) {}
  void send(int to, const dex::Message& m) override {
    TriggerSample s{run_id_, to, ++seq_, m};
    if (m.kind == dex::Message::Kind::ended) ++sent_;
    if (!node_.write(s)) ++write_errors_;
    changed();
  }
  /// One sample for the whole set: DDS hands it to every reader (one multicast packet on a
  /// network that has multicast). Counted once per drone that will take it.
  void send_to_set(const std::vector<int>& to, const dex::Message& m) override {
    TriggerSample s{run_id_, kEveryDrone, ++seq_, m};
    for (int d : to) sent_ += d != m.from ? 1 : 0;
    if (!node_.write(s)) ++write_errors_;
    changed();
  }
  void publish(std::shared_ptr<const dex::Telemetry> t) override {
    if (node_.write(TelemetrySample{run_id_, *t})) return;
    ++write_errors_;
    changed();
  }
  /// Called after every trigger sent and every failed write: the DEX publishes its counters
  /// and acts on a failure then, instead of looking for changes on a timer.
  void on_change(std::function<void()> fn) { on_change_ = std::move(fn); }
  std::uint64_t sent() const { return sent_; }
  std::uint64_t write_errors() const { return write_errors_; }

 private:
  DdsNode& node_;
  std::uint64_t run_id_;
  std::uint64_t seq_ = 0;
  std::uint64_t sent_ = 0;
  std::uint64_t write_errors_ = 0;
  std::function<void()> on_change_;
  void changed() {
    if (on_change_) on_change_();
  }
};

}  // namespace eamos::transport
