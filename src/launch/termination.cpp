#include "launch/termination.h"

#include <algorithm>

namespace eamos::launch {

std::uint64_t TerminationDetector::start_wave() {
  // The wave just finished becomes the previous one only if every drone answered it.
  Sums s = sums();
  previous_clean_ = !abandoned_ && wave_complete() && s.clean;
  previous_sent_ = s.sent;
  abandoned_ = false;
  ++wave_;
  std::fill(has_answer_.begin(), has_answer_.end(), false);
  answered_ = 0;
  return wave_;
}

void TerminationDetector::report(const WaveReport& r) {
  if (r.wave != wave_ || wave_ == 0 || r.drone < 0 || r.drone >= static_cast<int>(answers_.size())) return;
  if (has_answer_[r.drone]) return;  // the first answer is the one read during this wave
  has_answer_[r.drone] = true;
  answers_[r.drone] = r;
  ++answered_;
}

TerminationDetector::Sums TerminationDetector::sums() const {
  Sums s;
  s.clean = true;
  for (std::size_t d = 0; d < answers_.size(); ++d) {
    if (!has_answer_[d]) {
      s.clean = false;
      continue;
    }
    s.clean = s.clean && !answers_[d].busy;
    s.sent += answers_[d].sent;
    s.received += answers_[d].received;
  }
  s.clean = s.clean && s.sent == s.received;
  return s;
}

bool TerminationDetector::terminated() const {
  if (abandoned_ || !wave_complete() || !previous_clean_) return false;
  Sums s = sums();
  return s.clean && s.sent == previous_sent_;
}

void TerminationDetector::reset() {
  abandoned_ = true;
  previous_clean_ = false;
  std::fill(has_answer_.begin(), has_answer_.end(), false);
  answered_ = 0;
}

}  // namespace eamos::launch
