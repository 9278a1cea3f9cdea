#pragma once
// When a distributed mission is over: Mattern's four-counter method ("Algorithms for
// distributed termination detection", Distributed Computing 2, 1987) over the DEXes'
// status samples. The lead asks for a wave (its status names a new wave number); every
// drone answers once per wave with its busy flag and the messages it has sent and
// received. The mission is over when two consecutive waves, the second asked only after
// every answer to the first had come in, both found every drone idle and counted
// Σsent = Σreceived, the same in both. A message still in flight during the first wave is
// sent before it and received after it: the second wave then counts more received than
// the first counted sent, or finds its receiver busy, so it cannot pass unseen.
// (Idle-and-equal counts once, however long, can be fooled: a message sent after its
// sender's report and received before its receiver's balances one that is still on its way.)
#include <cstdint>
#include <vector>

namespace eamos::launch {

/// One drone's answer to a wave.
struct WaveReport {
  int drone = 0;
  std::uint64_t wave = 0;  ///< the wave it answers
  bool busy = false;       ///< an action, timer or watched condition active
  std::uint64_t sent = 0;      ///< messages this drone sent (each receiver counted)
  std::uint64_t received = 0;  ///< messages it received and accepted
};

class TerminationDetector {
 public:
  explicit TerminationDetector(int drones) : answers_(static_cast<std::size_t>(drones)) {}

  /// Starts the next wave and returns its number (from 1); answers to earlier waves are
  /// ignored from now on.
  std::uint64_t start_wave();
  /// The wave being collected (0: none yet).
  std::uint64_t wave() const { return wave_; }
  /// Takes a drone's first answer to the current wave; any other answer is ignored.
  void report(const WaveReport& r);
  /// Every drone answered the current wave.
  bool wave_complete() const { return answered_ == answers_.size(); }
  /// A wave is asked and its answers are still coming in.
  bool collecting() const { return wave_ > 0 && !abandoned_ && !wave_complete(); }
  /// The current wave is complete and clean (all idle, Σsent = Σreceived) and so was the
  /// one before it, with the same sums: nothing is running and nothing is in flight.
  bool terminated() const;
  /// Forgets the waves so far (the lead became busy again): the next two waves decide.
  void reset();

 private:
  struct Sums {
    bool clean = false;  ///< every answer idle and Σsent = Σreceived
    std::uint64_t sent = 0;
    std::uint64_t received = 0;
  };
  Sums sums() const;

  std::vector<WaveReport> answers_;  ///< per drone: its answer to the current wave
  std::vector<bool> has_answer_ = std::vector<bool>(answers_.size(), false);
  std::size_t answered_ = 0;
  std::uint64_t wave_ = 0;
  bool abandoned_ = false;       ///< reset() since the current wave started
  bool previous_clean_ = false;  ///< the wave before the current one was complete and clean
  std::uint64_t previous_sent_ = 0;
};

}  // namespace eamos::launch
