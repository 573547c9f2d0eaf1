#pragma once

// Which of a team's sizes a fast stepper runs its next step on (internal): the whole team or the
// calling thread alone, whichever took less time per unit of work lately. On a quiet machine two
// threads win; on one whose cores another job holds, the second thread's barrier waits cost more
// than it adds, and a step on one thread is faster. Results do not depend on the choice.

#include <algorithm>

namespace msfem::massspring::detail {

class AdaptiveThreads {
 public:
  AdaptiveThreads(int team_size, bool adaptive)
      : team_size_(team_size), adaptive_(adaptive && team_size > 1), current_(team_size) {}

  /// Runs of period steps on the current size, each followed by kProbe steps on the other.
  int choose() const {
    if (!adaptive_) return team_size_;
    const int other = current_ == 1 ? team_size_ : 1;
    return run_ < period_ ? current_ : other;
  }

  /// After a step on `members`: a probe 10 % faster than the run's last kProbe steps switches. The
  /// period doubles after each probe that does not switch (up to kMaxPeriod: the probes' cost on a
  /// steady machine stays near 1.5 %) and drops back to kMinPeriod after a switch.
  void record(int members, double seconds_per_unit) {
    last_ = members;
    if (!adaptive_) return;
    if (run_ >= period_ - kProbe && run_ < period_) current_time_ += seconds_per_unit;
    if (run_ >= period_) probe_time_ += seconds_per_unit;
    if (++run_ == period_ + kProbe) {
      const bool faster = probe_time_ < 0.9 * current_time_;
      if (faster) current_ = members;
      period_ = faster ? kMinPeriod : std::min(2 * period_, kMaxPeriod);
      run_ = 0;
      current_time_ = probe_time_ = 0.0;
    }
  }

  int last() const { return last_; }

 private:
  static constexpr int kMinPeriod = 32, kMaxPeriod = 256, kProbe = 4;
  int team_size_;
  bool adaptive_;
  int current_, last_ = 1, run_ = 0, period_ = kMinPeriod;
  double current_time_ = 0.0, probe_time_ = 0.0;
};

}  // namespace msfem::massspring::detail
