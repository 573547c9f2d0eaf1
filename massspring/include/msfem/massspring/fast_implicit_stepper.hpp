#pragma once

#include <memory>

#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mass_spring_model.hpp"

namespace msfem::massspring {

struct FastImplicitOptions {
  int threads = 2;
  bool reorder_nodes = true;
  /// Relative CG residual. Haptic loops stop early (1e-3) and warm-start from the last step's
  /// Δv; the step stays stable because the matrix is SPD and the error is damped by the next step.
  double cg_tolerance = 1e-3;
  int cg_max_iterations = 50;
  bool single_precision = false;  ///< float arithmetic and wider vectors
};

/// Backward Euler on the same structure-of-arrays layout and thread team as FastExplicitStepper
/// (Baraff & Witkin 1998): per step one pass linearises every spring (definite tangent
///   K_s = k [τ I + (1 - τ) n nᵀ], τ = max(0, 1 - l0/l), and damper c n nᵀ),
/// then Jacobi-preconditioned CG solves (M - h D - h² K) Δv = h (f + h K v) matrix-free, each
/// product a spring pass (y_s = α q + β (n·q) n, α = h² k τ, β = h c + h² k (1 - τ)) and a gather.
/// Tool contact is not applied. The model must outlive the stepper.
class FastImplicitStepper {
 public:
  explicit FastImplicitStepper(const MassSpringModel& model,
                               const FastImplicitOptions& options = {});
  ~FastImplicitStepper();
  FastImplicitStepper(const FastImplicitStepper&) = delete;
  FastImplicitStepper& operator=(const FastImplicitStepper&) = delete;

  void update_parameters(const MassSpringModel& model);
  void set_state(const State& state);
  State state() const;
  /// One backward-Euler step. Throws ModelError for a bad dt.
  void step(double dt);
  int last_cg_iterations() const;
  int num_nodes() const;
  int num_springs() const;

  class Implementation;

 private:
  std::unique_ptr<Implementation> impl_;
};

}  // namespace msfem::massspring
