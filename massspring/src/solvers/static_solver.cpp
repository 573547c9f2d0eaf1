// Newton's method with line search for the static equilibrium of a spring network.

#include "msfem/massspring/static_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/nodal_load_field.hpp"
#include "node_relaxation.hpp"
#include "static_linear.hpp"

namespace msfem::massspring {
namespace {

using detail::FreeDofs;
using detail::KrylovOutcome;
using SparseMatrix = Eigen::SparseMatrix<double>;

// Nodal relaxation visits the nodes whose residual force is at least this fraction of the
// largest, this many times: on the brain these are the few dozen ends of the folded springs.
constexpr double relaxation_fraction = 0.01;
constexpr int relaxation_sweeps = 2;

bool solve_jacobi_cg(const SparseMatrix& k, const Eigen::VectorXd& r, Eigen::VectorXd& d,
                     const StaticOptions& options) {
  const Eigen::VectorXd inverse_diagonal = k.diagonal().cwiseMax(1e-300).cwiseInverse();
  d = Eigen::VectorXd::Zero(r.size());
  Eigen::VectorXd residual = r;
  Eigen::VectorXd z = inverse_diagonal.cwiseProduct(residual);
  Eigen::VectorXd p = z;
  double rz = residual.dot(z);
  const double target = options.cg_tolerance * r.norm();
  int it = 0;
  for (; it < options.cg_max_iterations && residual.norm() > target; ++it) {
    const Eigen::VectorXd kp = k * p;
    const double pkp = p.dot(kp);
    if (!(pkp > 0.0)) return false;
    const double alpha = rz / pkp;
    d += alpha * p;
    residual -= alpha * kp;
    z = inverse_diagonal.cwiseProduct(residual);
    const double rz_next = residual.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  return d.allFinite() && it < options.cg_max_iterations;
}

// Finds Newton directions. Keeps the last factorisation (and its symbolic analysis) between
// iterations, where it preconditions CG on the next tangent.
class DirectionFinder {
 public:
  DirectionFinder(const MechanicalSystem& model, const FreeDofs& dofs, const StaticOptions& options)
      : model_(model),
        dofs_(dofs),
        options_(options),
        free_mass_(dofs.gather(model.mass_per_dof())),
        factor_(options.factorization ? options.factorization() : nullptr) {}

  // d with d·r > 0 (a descent direction for the energy); false if every linearisation is singular.
  bool find(const Eigen::VectorXd& x, const Eigen::VectorXd& r, double linear_tolerance,
            Eigen::VectorXd& d, StaticIteration& record) {
    const bool ldlt = options_.linear_solver == StaticLinearSolver::sparse_ldlt;
    const bool reuse = ldlt && options_.reuse_factorization;
    // The exact tangent gives quadratic convergence near a stable equilibrium: tried first.
    bool exact_indefinite = false;
    if (reuse && factor_.valid()) {
      const KrylovOutcome outcome =
          preconditioned(x, Linearisation::exact, r, linear_tolerance, d, record);
      if (outcome == KrylovOutcome::converged && d.dot(r) > 0.0) {
        record.step = StaticStep::exact_preconditioned;
        return true;
      }
      exact_indefinite = outcome == KrylovOutcome::negative_curvature;
    }
    if (ldlt && !exact_indefinite) {
      if (factorized(free_stiffness(model_, x, dofs_, Linearisation::exact), r, d)) {
        record.step = StaticStep::exact_factorized;
        return true;
      }
    }
    // Here the factor is still the previous iteration's only if CG just proved the exact
    // tangent indefinite; it then preconditions the definite linearisation as well.
    if (reuse && factor_.valid() && shift_ == 0.0) {
      const KrylovOutcome outcome =
          preconditioned(x, Linearisation::definite, r, linear_tolerance, d, record);
      if (outcome == KrylovOutcome::converged && d.dot(r) > 0.0) {
        record.step = StaticStep::definite_preconditioned;
        return true;
      }
    }
    const SparseMatrix k = free_stiffness(model_, x, dofs_, Linearisation::definite);
    auto solve = [&](const SparseMatrix& matrix) {
      return ldlt ? factorized(matrix, r, d)
                  : solve_jacobi_cg(matrix, r, d, options_) && d.dot(r) > 0.0;
    };
    record.step = ldlt ? StaticStep::definite_factorized : StaticStep::jacobi_cg;
    if (shift_ == 0.0 && solve(k)) return true;
    // Mechanisms (e.g. the three-tier shell turning on its radial springs, which have no
    // stiffness across them at rest) make K singular. Shift by μM, a pseudo time step of size
    // 1/√μ: still a descent direction, and the shift does not move the solution.
    const double k_scale = k.diagonal().cwiseAbs().mean();
    const double m_scale = free_mass_.mean();
    for (double trial = shift_ > 0.0 ? std::max(shift_ / 100.0, 1e-10) : 1e-10; trial <= 1.0;
         trial *= 100.0) {
      SparseMatrix shifted = k;
      for (int j = 0; j < dofs_.size(); ++j)
        shifted.coeffRef(j, j) += trial * k_scale / m_scale * free_mass_[j];
      if (solve(shifted)) {
        shift_ = trial;
        if (ldlt) record.step = StaticStep::shifted;
        record.shift = trial;
        return true;
      }
    }
    shift_ = 0.0;
    return false;
  }

  int factorizations() const { return factor_.factorizations(); }

 private:
  bool factorized(const SparseMatrix& k, const Eigen::VectorXd& r, Eigen::VectorXd& d) {
    if (!factor_.factorize(k)) return false;
    d = factor_.solve(r);
    return d.allFinite() && d.dot(r) > 0.0;
  }

  KrylovOutcome preconditioned(const Eigen::VectorXd& x, Linearisation mode,
                               const Eigen::VectorXd& r, double tolerance, Eigen::VectorXd& d,
                               StaticIteration& record) {
    const detail::TangentOperator k(model_, dofs_, x, mode);
    int iterations = 0;
    const KrylovOutcome outcome =
        detail::preconditioned_cg([&](const Eigen::VectorXd& v) { return k * v; }, factor_, r,
                                  tolerance, options_.max_preconditioned_iterations, d, iterations);
    record.preconditioned_iterations += iterations;
    return outcome;
  }

  const MechanicalSystem& model_;
  const FreeDofs& dofs_;
  const StaticOptions& options_;
  const Eigen::VectorXd free_mass_;
  detail::TangentFactor factor_;
  double shift_ = 0.0;  // last μ that made the shifted tangent positive definite
};

struct LineSearchResult {
  double alpha = 1.0;
  Eigen::VectorXd x, f;  // state and full force at x + αd
};

// Line search on U(x + αd), whose slope is -f(x + αd)·d: sufficient decrease (Armijo) and a
// strong-Wolfe curvature test |U'(α)| <= c2 |U'(0)|, reached by interpolation when the step is
// too long and by secant extrapolation when it is too short. Too short is common on the brain:
// along its near-mechanisms U stiffens faster than quadratically, a full Newton step covers only
// part of the way, and plain backtracking never lengthens it.
LineSearchResult line_search(const MechanicalSystem& model, const FreeDofs& dofs,
                             const Eigen::VectorXd& x, const Eigen::VectorXd& r,
                             const Eigen::VectorXd& d, double target, bool wolfe) {
  constexpr double c1 = 1e-4;
  constexpr double c2 = 0.1;
  constexpr int max_trials = 8;
  struct Point {
    double alpha, energy, slope;
  };
  const double energy0 = model.potential_energy(x);
  const double slope0 = -d.dot(r);
  // Near convergence the energy change drowns in round-off; such steps count as decreasing.
  const double noise = 1e-13 * std::abs(energy0) + 1e-300;
  auto decreases = [&](const Point& p) {
    return p.energy <= energy0 + c1 * p.alpha * slope0 || std::abs(p.energy - energy0) <= noise;
  };
  LineSearchResult trial;
  auto evaluate = [&](double alpha) {
    trial.alpha = alpha;
    trial.x = x;
    dofs.scatter_add(d, alpha, trial.x);
    trial.f = model.force(trial.x, Eigen::VectorXd::Zero(x.size()));
    return Point{alpha, model.potential_energy(trial.x), -d.dot(dofs.gather(trial.f))};
  };
  double alpha = 1.0;
  if (wolfe) {
    Point lo{0.0, energy0, slope0}, previous = lo, hi{};
    bool have_hi = false, have_best = false;
    LineSearchResult best;
    for (int n = 0; n < max_trials; ++n) {
      const Point p = evaluate(alpha);
      if (decreases(p) && p.energy <= lo.energy + noise) {
        best = trial;
        have_best = true;
        if (std::abs(p.slope) <= c2 * std::abs(slope0) || dofs.gather(trial.f).norm() <= target)
          return best;
        if (p.slope > 0.0) {
          hi = p;
          have_hi = true;
        } else {
          previous = lo;
          lo = p;
        }
      } else {
        hi = p;
        have_hi = true;
      }
      const double width = hi.alpha - lo.alpha;
      double next;
      if (have_hi) {
        next = hi.slope > 0.0 && hi.energy <= energy0 + noise
                   ? lo.alpha - lo.slope * width / (hi.slope - lo.slope)  // secant on U'
                   : lo.alpha - 0.5 * lo.slope * width * width /          // quadratic on U
                                    (hi.energy - lo.energy - lo.slope * width);
        if (!std::isfinite(next)) next = lo.alpha + 0.5 * width;
        alpha = std::clamp(next, lo.alpha + 0.1 * width, hi.alpha - 0.1 * width);
      } else {
        // Still descending: extrapolate U' to zero, at least doubling and at most ×4.
        next = lo.slope > previous.slope
                   ? lo.alpha - lo.slope * (lo.alpha - previous.alpha) / (lo.slope - previous.slope)
                   : 4.0 * lo.alpha;
        alpha =
            std::clamp(std::isfinite(next) ? next : 4.0 * lo.alpha, 2.0 * lo.alpha, 4.0 * lo.alpha);
      }
    }
    if (have_best) return best;
    alpha = std::min(alpha, 1.0);  // no decrease found yet: go on backtracking from here
  }
  // Armijo backtracking.
  for (int halving = 0; halving < 40; ++halving, alpha *= 0.5)
    if (decreases(evaluate(alpha))) break;
  return trial;
}

// |f_free| of the applied loads (gravity, external forces) and of the initial state, whose
// larger is the scale of the problem: neither depends on where Newton starts.
double reference_norm(const MechanicalSystem& model, const FreeDofs& dofs) {
  const auto* loads = model.find_field<NodalLoadField>();
  double load_norm_squared = 0.0;
  for (int i = 0; i < model.num_nodes(); ++i)
    if (loads && !model.is_constrained(i)) load_norm_squared += loads->load(i).squaredNorm();
  const Eigen::VectorXd x0 = model.initial_state();
  const double initial = dofs.gather(model.force(x0, Eigen::VectorXd::Zero(x0.size()))).norm();
  return std::max(std::sqrt(load_norm_squared), initial);
}

// The force residual round-off leaves: each force is a sum of k (|x_a − x_b| − l) terms whose
// positions carry a relative error ε, so |f| cannot be resolved below about ε k_max |x| per
// coordinate. A target under it is met by no iterate, and Newton then wanders (along an
// indefinite tangent, or with steps the line search cannot judge) instead of stopping.
double roundoff_floor(const MechanicalSystem& model, const FreeDofs& dofs,
                      const Eigen::VectorXd& x) {
  double x_scale = 0.0;
  for (int k : dofs.full_index)
    x_scale = std::max(x_scale, std::abs(x[k]));
  const double k_max =
      free_stiffness(model, x, dofs, Linearisation::definite).diagonal().cwiseAbs().maxCoeff();
  return 16.0 * std::numeric_limits<double>::epsilon() * k_max * x_scale *
         std::sqrt(double(dofs.size()));
}

}  // namespace

StaticResult solve_static(const MechanicalSystem& model, const StaticOptions& options,
                          const Eigen::VectorXd& start) {
  const FreeDofs dofs(model);
  StaticResult result;
  result.x = start.size() == model.num_dofs() ? start : model.initial_state();
  Eigen::VectorXd zero_v = Eigen::VectorXd::Zero(model.num_dofs());
  model.enforce_constraints(result.x, zero_v);
  if (dofs.size() == 0) {
    result.converged = true;
    return result;
  }
  Eigen::VectorXd f = model.force(result.x, zero_v);
  Eigen::VectorXd r = dofs.gather(f);
  result.residual_norm = r.norm();
  result.reference_norm = reference_norm(model, dofs);
  if (!(result.reference_norm > 0.0)) {
    result.converged = true;  // unloaded and at rest: already in equilibrium
    return result;
  }
  const double target = options.tolerance * result.reference_norm;
  const double floor = roundoff_floor(model, dofs, result.x);

  DirectionFinder directions(model, dofs, options);
  const detail::NodeRelaxation relaxation(model);
  double previous_norm = 0.0, eta = 0.1;
  while (result.residual_norm > target && result.iterations < options.max_iterations) {
    ++result.iterations;
    // Inexact Newton (Eisenstat-Walker choice 2): solve loosely while |f| falls slowly, tightly
    // once it falls quadratically; never much below the target.
    if (previous_norm > 0.0) {
      const double ratio = result.residual_norm / previous_norm;
      eta = std::min(0.5,
                     std::max(0.9 * ratio * ratio, 0.9 * eta * eta > 0.1 ? 0.9 * eta * eta : 0.0));
    }
    previous_norm = result.residual_norm;
    const double linear_tolerance = std::max(eta * result.residual_norm, 0.1 * target);
    Eigen::VectorXd d;
    StaticIteration record;
    if (!directions.find(result.x, r, linear_tolerance, d, record))
      throw ModelError("static equilibrium: tangent stiffness is singular at Newton iteration " +
                       std::to_string(result.iterations) +
                       " (free nodes not supported? fix nodes or add anchors)");
    result.preconditioned_iterations += record.preconditioned_iterations;

    // A step below the resolution of x cannot lower |f| further: |f| is at its round-off floor.
    double x_scale = 0.0;
    for (int k : dofs.full_index)
      x_scale = std::max(x_scale, std::abs(result.x[k]));
    if (d.cwiseAbs().maxCoeff() <= 8.0 * std::numeric_limits<double>::epsilon() * x_scale) {
      result.converged_at_roundoff = true;
      record.residual_norm = result.residual_norm;
      record.step_length = 0.0;
      result.history.push_back(record);
      break;
    }

    LineSearchResult step =
        line_search(model, dofs, result.x, r, d, target, options.wolfe_line_search);
    result.x = std::move(step.x);
    f = std::move(step.f);
    r = dofs.gather(f);
    if (options.relax_nodes && r.norm() > target) {
      relaxation.relax(result.x, f, relaxation_fraction, relaxation_sweeps);
      f = model.force(result.x, zero_v);
      r = dofs.gather(f);
    }
    result.residual_norm = r.norm();
    record.residual_norm = result.residual_norm;
    record.step_length = step.alpha;
    result.history.push_back(record);
    if (result.residual_norm > target && result.residual_norm <= floor) {
      result.converged_at_roundoff = true;
      break;
    }
  }
  result.factorizations = directions.factorizations();
  result.converged = result.residual_norm <= target || result.converged_at_roundoff;
  return result;
}

}  // namespace msfem::massspring
