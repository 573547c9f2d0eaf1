#pragma once

// When the fast implicit stepper starts CG from the trend of its last steps (internal). The plain
// warm start is the last step's Δv; the trend start adds θ (Δv_n − Δv_n−1), θ the least-squares
// fit of the last change on the one before, in [0, 1]. It pays where CG converges slowly: on the
// brain with volume preservation on its prisms, 19 iterations a step from the plain start in the
// bench, it halves them. Where CG converges in about three (the brain's springs alone, the tet
// model), the plain start is already within a few tolerances of the solution and what is left is
// mostly the last solve's error in the stiff modes, which decay within a step and which a trend
// doubles: the fitted trend start cost the brain half an iteration a step (3.4 → 3.9), a half
// trend saved it 8 % and cost the tet model 7 %. So it is taken only while the steps need many
// iterations. Results stay those of a CG solve to the stepper's tolerance from either start; the
// choice depends on iteration counts only.

namespace msfem::massspring::detail {

class WarmStartTrend {
 public:
  /// Whether the last kWindow steps needed kSlow CG iterations or more on average.
  bool slow() const { return window_sum_ >= kSlow * kWindow; }

  /// After a step: its CG iterations.
  void record(int iterations) {
    window_sum_ += iterations - window_[next_];
    window_[next_] = iterations;
    next_ = (next_ + 1) % kWindow;
  }

 private:
  static constexpr int kWindow = 8, kSlow = 6;
  int window_[kWindow] = {};
  int next_ = 0, window_sum_ = 0;
};

}  // namespace msfem::massspring::detail
