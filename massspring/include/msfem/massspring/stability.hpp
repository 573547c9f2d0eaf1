#pragma once

#include <Eigen/Core>
#include <string>

#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mechanical_system.hpp"

namespace msfem::massspring {

/// Largest eigenvalue of M⁻¹K on the free dofs (K = -∂f/∂x, definite linearisation at x), by
/// power iteration on the symmetric M^-½ K M^-½. Its square root is the highest natural
/// frequency ω_max (rad/s).
struct SpectralEstimate {
  double max_eigenvalue = 0.0;     ///< ω_max², 1/s²
  double mode_damping_rate = 0.0;  ///< γ = yᵀCy / yᵀMy of that mode y (C = -∂f/∂v), 1/s
  int iterations = 0;
};
SpectralEstimate estimate_max_eigenvalue(const MechanicalSystem& model, const Eigen::VectorXd& x,
                                         int max_iterations = 300, double tolerance = 1e-5);

/// Stable time step predicted from ω_max and the damping (linear stability of each method on the
/// highest mode, γ its damping rate): symplectic Euler and central difference
/// (√(γ² + 4ω²) - γ)/ω², i.e. 2/ω undamped; RK4 2√2/ω; explicit Euler
/// -2 Re λ / |λ|² for the mode's eigenvalues λ = -γ/2 ± √(γ²/4 - ω²), i.e. γ/ω² when underdamped
/// (zero when undamped: explicit Euler then always grows), implicit Euler +∞.
double predicted_stable_dt(const MechanicalSystem& model, IntegratorKind kind,
                           const Eigen::VectorXd& x);

/// Largest dt for which `steps` steps from a small random perturbation of the rest state (loads and
/// tool removed, supports kept) stay bounded, by bisection in [dt_low, dt_high] to a relative
/// width `relative_tolerance`. "Bounded" = no divergence and final T + U ≤ 10 × initial.
double measure_stable_dt(const MechanicalSystem& model, IntegratorKind kind, double dt_low,
                         double dt_high, int steps = 2000, double relative_tolerance = 0.01);

/// Why a state counts as diverged ("" when it does not): a non-finite position or velocity, or a
/// spring stretched beyond (1 + max_strain) × or compressed below 1/(1 + max_strain) × its rest
/// length. Exponential blow-up crosses either within a step or two of becoming visible.
std::string divergence_reason(const MechanicalSystem& model, const State& state,
                              double max_strain = 5.0);

struct RunOptions {
  double max_strain = 5.0;  ///< see divergence_reason
  int check_every = 1;      ///< steps between checks (1 = every step)
};

/// Runs `steps` steps of size dt, checking each state. On a blow-up throws DivergenceError whose
/// message names the step, the time, dt, the reason, and the predicted stable dt for this
/// integrator; the state is left at the failing step.
void run_dynamics(const MechanicalSystem& model, Integrator& integrator, State& state, double dt,
                  int steps, const RunOptions& options = {});

}  // namespace msfem::massspring
