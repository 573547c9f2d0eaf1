#pragma once

#include <Eigen/Core>

#include "msfem/massspring/mass_spring_model.hpp"

namespace msfem::massspring {

enum class StaticLinearSolver {
  sparse_ldlt,  ///< Eigen SimplicialLDLT on the free-dof tangent stiffness
  cg            ///< Jacobi-preconditioned conjugate gradients (definite linearisation)
};

struct StaticOptions {
  StaticLinearSolver linear_solver = StaticLinearSolver::sparse_ldlt;
  int max_iterations = 100;
  /// Converged when |f_free| <= tolerance × max(|applied loads|, |f_free at start|).
  double tolerance = 1e-11;
  double cg_tolerance = 1e-12;
  int cg_max_iterations = 5000;
};

struct StaticResult {
  Eigen::VectorXd x;  ///< node-major positions at equilibrium
  int iterations = 0;
  double residual_norm = 0.0;   ///< |f| on free dofs, N
  double reference_norm = 0.0;  ///< the scale the tolerance multiplies
  bool converged = false;
};

/// Static equilibrium f(x) = 0 on the free dofs (constrained nodes at their targets, tool contact
/// included) by Newton's method with a backtracking (Armijo) line search on the potential energy.
/// The exact tangent is tried first; if it is not positive definite (compressed springs, buckling)
/// the definite linearisation is used for that iteration. Starts from `start` when it has the right
/// size, else from the initial state. Throws ModelError if the free dofs are unsupported (singular
/// stiffness: add supports or anchors).
StaticResult solve_static(const MassSpringModel& model, const StaticOptions& options = {},
                          const Eigen::VectorXd& start = Eigen::VectorXd());

}  // namespace msfem::massspring
