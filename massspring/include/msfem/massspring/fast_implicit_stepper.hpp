#pragma once

#include <memory>

#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mechanical_system.hpp"
#include "msfem/massspring/stepper.hpp"

namespace msfem::massspring {

/// The tightest CG tolerance at which a double solve keeps its springs' coefficients in float
/// (FastImplicitOptions::single_precision_terms).
constexpr double kSingleTermsTolerance = 1e-6;

struct FastImplicitOptions {
  int threads = 2;
  bool reorder_nodes = true;
  /// Relative CG residual, ‖b - A Δv‖ <= cg_tolerance ‖b‖. The haptic default 1e-2, with the
  /// warm start from the last step's Δv, keeps positions within ~1e-3 (relative to the
  /// displacement) of a tight solve over 100 steps at dt = 1 ms on a small loaded sphere (a test
  /// checks it); on the brain's three tiers released from a 2 % dilation, 4.4e-2, all of it in
  /// the release's first 50 steps (1e-4: 5.5e-4). Use 1e-8 or below for a reference-quality step.
  /// Near rest, where b is down to the rounding of its spring forces (u k l0 a spring end, u the
  /// precision's unit round-off), the CG stops at that instead: a smaller residual would fit the
  /// rounding.
  double cg_tolerance = 1e-2;
  /// Cap on CG iterations per step: bounds a haptic step's time. A step that reaches it is not
  /// solved to cg_tolerance; last_cg_iterations() tells.
  int cg_max_iterations = 50;
  bool single_precision = false;  ///< float arithmetic and wider vectors
  /// With threads > 1: step on the calling thread alone while that is faster (when other programs
  /// hold the cores, every one of a step's ~15 barriers waits for a pre-empted thread). Measured
  /// per step, re-checked by 4 steps on the other count after every 32 to 256 steps. Results do not
  /// depend on it: sums are taken per block of nodes in a fixed order, for any number of threads
  /// (a force field's parts are summed per thread, so with one only to rounding).
  bool adaptive_threads = true;
  /// In double precision, keep the springs' per-step system coefficients (α and e below: what
  /// every CG product streams, 32 bytes a spring end) in float where the solve is loose,
  /// cg_tolerance >= kSingleTermsTolerance: the products stream half the bytes. The system they
  /// apply is then the double one rounded to float per coefficient (relative 6e-8, symmetric as
  /// before), far inside such a tolerance; state, right-hand side, preconditioner and CG vectors
  /// stay double. Tighter tolerances keep every coefficient double.
  bool single_precision_terms = true;
  /// Where CG converges slowly (the last 8 steps took 6 iterations or more on average), start it
  /// from the trend of the last steps, Δv_n + θ (Δv_n - Δv_n-1), θ fitted to the last two
  /// changes, instead of Δv_n: on the brain with volume preservation on its prisms that halves
  /// the iterations. Where CG converges in a few iterations the trend start does not pay and is
  /// not taken. Only the start changes: every step is still solved to cg_tolerance. The trend is
  /// kept over steps of one dt: a step of another dt (compared exactly) starts it anew.
  bool trend_start = true;
};

/// Backward Euler on the same node-centric layout, kernels and thread team as FastExplicitStepper
/// (Baraff & Witkin 1998): per step one pass linearises every spring (definite tangent
///   K_s = k [τ I + (1 - τ) n nᵀ], τ = max(0, 1 - l0/l), and damper c n nᵀ)
/// and, in the same pass, starts CG from the last step's Δv or its trend (r = b - A Δv,
/// FastImplicitOptions::trend_start); then CG preconditioned by the 3x3 diagonal blocks solves
/// (M - h D - h² K) Δv = h (f + h K v) matrix-free, in the Chronopoulos-Gear form (one pass over
/// the nodes and one reduction per product; the same iterates as plain CG in exact arithmetic).
/// Each product is one gather over the springs (per spring and end y += α q + (e·q) e,
/// α = h² k τ, e = √(h c + h² k (1 - τ)) n). The model's force
/// fields (the tool's contact, volume preservation) enter the same system through their
/// ForceField calls at their nodes: force and definite ∂f/∂x, ∂f/∂v products, and their diagonal
/// blocks in the preconditioner (one more barrier per product), and a field on every node
/// (volume preservation) shares its elements among the threads. The model must outlive the
/// stepper.
class FastImplicitStepper : public Stepper {
 public:
  explicit FastImplicitStepper(const MechanicalSystem& model,
                               const FastImplicitOptions& options = {});
  ~FastImplicitStepper();
  FastImplicitStepper(const FastImplicitStepper&) = delete;
  FastImplicitStepper& operator=(const FastImplicitStepper&) = delete;

  void update_parameters(const MechanicalSystem& model) override;
  void set_state(const State& state) override;
  State state() const override;
  /// `count` backward-Euler steps. Throws ModelError for a bad dt.
  void step(double dt, int count = 1) override;
  IntegratorKind kind() const override { return IntegratorKind::implicit_euler; }
  const char* name() const override { return "fast_implicit"; }
  const char* precision() const override { return single_ ? "float" : "double"; }
  int last_cg_iterations() const;
  /// Threads the last step ran on (1 while adaptive_threads found one faster).
  int last_step_threads() const;
  /// Whether this double solve keeps its springs' coefficients in float
  /// (FastImplicitOptions::single_precision_terms and a loose enough cg_tolerance).
  bool single_precision_terms() const;
  int num_nodes() const;
  int num_springs() const;

  class Implementation;

 private:
  std::unique_ptr<Implementation> impl_;
  bool single_;
};

}  // namespace msfem::massspring
