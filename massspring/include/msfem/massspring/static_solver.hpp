#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
#include <vector>

#include "msfem/massspring/mechanical_system.hpp"

namespace msfem::massspring {

enum class StaticLinearSolver {
  sparse_ldlt,  ///< Eigen SimplicialLDLT on the free-dof tangent stiffness
  cg            ///< Jacobi-preconditioned conjugate gradients (definite linearisation)
};

/// A sparse symmetric positive definite factorisation the static solver can use in place of
/// Eigen's SimplicialLDLT: a simulator plugs in the direct solver it already links (CHOLMOD,
/// PARDISO, ...) without this library depending on it. `msfem` plugs in CHOLMOD's supernodal
/// Cholesky, many times faster on the three-dimensional tet_edges networks.
class SparseSpdFactor {
 public:
  virtual ~SparseSpdFactor() = default;
  /// Symbolic analysis (ordering) for k's pattern; called again only when the pattern changes.
  virtual void analyze(const Eigen::SparseMatrix<double>& k) = 0;
  /// Numeric factorisation of k (full symmetric storage); false if k is not numerically
  /// positive definite.
  virtual bool factorize(const Eigen::SparseMatrix<double>& k) = 0;
  virtual Eigen::VectorXd solve(const Eigen::VectorXd& r) const = 0;
};

struct StaticOptions {
  /// Makes the factorisation sparse_ldlt uses; empty: Eigen's SimplicialLDLT (AMD ordering).
  std::function<std::unique_ptr<SparseSpdFactor>()> factorization;
  StaticLinearSolver linear_solver = StaticLinearSolver::sparse_ldlt;
  int max_iterations = 100;
  /// Converged when |f_free| <= tolerance × max(|applied loads|, |f_free at the initial state|),
  /// or when the Newton step no longer moves any free coordinate beyond its round-off.
  double tolerance = 1e-11;
  double cg_tolerance = 1e-12;
  int cg_max_iterations = 5000;
  // The three switches below change the path to the equilibrium, not the equations or the
  // tolerance; all off is plain damped Newton with one factorisation per iteration.
  /// sparse_ldlt: solve each Newton system first by conjugate gradients preconditioned with the
  /// last factorisation (to the Eisenstat-Walker tolerance), and factorise again only when that
  /// meets negative curvature or needs more than `max_preconditioned_iterations`. On the brain a
  /// factorisation costs as much as ~80 preconditioned iterations.
  bool reuse_factorization = true;
  int max_preconditioned_iterations = 30;
  /// After each Newton step, move the free nodes with the largest residual force one at a time
  /// to their own energy minimum, the others held (nonlinear Gauss-Seidel; it only lowers the
  /// energy). Removes the stalls that microns-long stiff springs (folded inner tiers) cause.
  bool relax_nodes = true;
  /// Line search that also lengthens too-short steps (strong Wolfe); off: Armijo backtracking.
  bool wolfe_line_search = true;
};

/// How one Newton direction was found.
enum class StaticStep {
  exact_factorized,         ///< LDLT of the exact tangent
  exact_preconditioned,     ///< CG on the exact tangent, preconditioned by an earlier LDLT
  definite_factorized,      ///< LDLT of the definite linearisation (exact one not definite)
  definite_preconditioned,  ///< CG on the definite linearisation, preconditioned
  shifted,                  ///< LDLT of the definite linearisation + μM (mechanisms)
  jacobi_cg                 ///< StaticLinearSolver::cg
};

struct StaticIteration {
  double residual_norm = 0.0;  ///< |f_free| after the step, N
  double step_length = 1.0;    ///< line-search α
  StaticStep step = StaticStep::exact_factorized;
  double shift = 0.0;                 ///< μ when step == shifted
  int preconditioned_iterations = 0;  ///< CG iterations spent on this direction (all attempts)
};

struct StaticResult {
  Eigen::VectorXd x;  ///< node-major positions at equilibrium
  int iterations = 0;
  double residual_norm = 0.0;   ///< |f| on free dofs, N
  double reference_norm = 0.0;  ///< the scale the tolerance multiplies
  bool converged = false;
  /// Converged because the Newton step fell below the resolution of doubles at x while |f| was
  /// still above the tolerance: |f| is then at its round-off floor (cancellation in the spring
  /// forces), which on the brain lies near 1e-11 × the reference; or because |f| fell below that
  /// floor, estimated as 16 ε k_max |x|_max √n (k_max the largest diagonal stiffness).
  bool converged_at_roundoff = false;
  int factorizations = 0;                ///< LDLT factorisations, the dominant cost
  int preconditioned_iterations = 0;     ///< CG iterations with a reused factorisation
  std::vector<StaticIteration> history;  ///< one entry per Newton iteration
};

/// Static equilibrium f(x) = 0 on the free dofs (constrained nodes at their targets, tool contact
/// included) by Newton's method with a line search on the potential energy. The exact tangent is
/// tried first; if it is not positive definite (compressed springs, buckling) the definite
/// linearisation is used for that iteration. Starts from `start` when it has the right size, else
/// from the initial state; the tolerance does not depend on the start, so a warm start from an
/// equilibrium returns at once. Like any descent method it finds the equilibrium whose basin it
/// starts in: a network with several (a folded or symmetric one that buckles) may end in another
/// one than with other options or another start, and an exactly symmetric problem can end on a
/// symmetric saddle. Throws ModelError if the free dofs are unsupported (singular stiffness: add
/// supports or anchors).
StaticResult solve_static(const MechanicalSystem& model, const StaticOptions& options = {},
                          const Eigen::VectorXd& start = Eigen::VectorXd());

}  // namespace msfem::massspring
