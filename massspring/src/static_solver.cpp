// Newton's method with line search for the static equilibrium of a spring network.

#include "msfem/massspring/static_solver.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cmath>

#include "msfem/massspring/errors.hpp"

namespace msfem::massspring {
namespace {

// Maps full dofs to free dofs (-1 for constrained).
struct FreeDofs {
  std::vector<int> free_index;
  std::vector<int> full_index;
};

FreeDofs free_dofs(const MassSpringModel& model) {
  FreeDofs dofs;
  dofs.free_index.assign(model.num_dofs(), -1);
  for (int i = 0; i < model.num_nodes(); ++i) {
    if (model.is_constrained(i)) continue;
    for (int c = 0; c < 3; ++c) {
      dofs.free_index[3 * i + c] = static_cast<int>(dofs.full_index.size());
      dofs.full_index.push_back(3 * i + c);
    }
  }
  return dofs;
}

// K = -∂f/∂x restricted to the free dofs.
Eigen::SparseMatrix<double> free_stiffness(const MassSpringModel& model, const Eigen::VectorXd& x,
                                           const FreeDofs& dofs, Linearisation mode) {
  Triplets all;
  model.add_dfdx_triplets(x, Eigen::VectorXd::Zero(x.size()), all, mode);
  Triplets free;
  free.reserve(all.size());
  for (const auto& t : all) {
    const int r = dofs.free_index[t.row()];
    const int c = dofs.free_index[t.col()];
    if (r >= 0 && c >= 0) free.emplace_back(r, c, -t.value());
  }
  const int n = static_cast<int>(dofs.full_index.size());
  Eigen::SparseMatrix<double> k(n, n);
  k.setFromTriplets(free.begin(), free.end());
  return k;
}

// Solves K d = r on the free dofs; returns false if K is not (numerically) positive definite.
bool solve_ldlt(const Eigen::SparseMatrix<double>& k, const Eigen::VectorXd& r,
                Eigen::VectorXd& d) {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(k);
  if (ldlt.info() != Eigen::Success) return false;
  const Eigen::VectorXd pivots = ldlt.vectorD();
  if (!((pivots.array() > 1e-12 * pivots.cwiseAbs().maxCoeff()).all())) return false;
  d = ldlt.solve(r);
  return ldlt.info() == Eigen::Success && d.allFinite();
}

bool solve_cg(const Eigen::SparseMatrix<double>& k, const Eigen::VectorXd& r, Eigen::VectorXd& d,
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

}  // namespace

StaticResult solve_static(const MassSpringModel& model, const StaticOptions& options,
                          const Eigen::VectorXd& start) {
  const FreeDofs dofs = free_dofs(model);
  const int n_free = static_cast<int>(dofs.full_index.size());
  StaticResult result;
  result.x = start.size() == model.num_dofs() ? start : model.initial_state();
  Eigen::VectorXd zero_v = Eigen::VectorXd::Zero(model.num_dofs());
  model.enforce_constraints(result.x, zero_v);
  if (n_free == 0) {
    result.converged = true;
    return result;
  }

  const Eigen::VectorXd all_mass = model.mass_per_dof();
  Eigen::VectorXd free_mass(n_free);
  for (int k = 0; k < n_free; ++k)
    free_mass[k] = all_mass[dofs.full_index[k]];
  auto free_residual = [&](const Eigen::VectorXd& x) {
    const Eigen::VectorXd f = model.force(x, Eigen::VectorXd::Zero(x.size()));
    Eigen::VectorXd r(n_free);
    for (int k = 0; k < n_free; ++k)
      r[k] = f[dofs.full_index[k]];
    return r;
  };
  // Scale of the applied loads (gravity and external forces on free nodes).
  double load_norm_squared = 0.0;
  for (int i = 0; i < model.num_nodes(); ++i)
    if (!model.is_constrained(i))
      load_norm_squared += (model.network().masses[i] * model.gravity()).squaredNorm();
  Eigen::VectorXd r = free_residual(result.x);
  result.reference_norm = std::max(std::sqrt(load_norm_squared), r.norm());
  if (!(result.reference_norm > 0.0)) {
    result.converged = true;  // unloaded and at rest: already in equilibrium
    return result;
  }
  const double target = options.tolerance * result.reference_norm;

  double shift = 0.0;  // last μ that made the shifted tangent positive definite
  for (int iteration = 1; iteration <= options.max_iterations; ++iteration) {
    result.residual_norm = r.norm();
    if (result.residual_norm <= target) {
      result.converged = true;
      break;
    }
    result.iterations = iteration;
    Eigen::VectorXd d;
    bool solved = false;
    auto solve = [&](const Eigen::SparseMatrix<double>& k) {
      return options.linear_solver == StaticLinearSolver::sparse_ldlt ? solve_ldlt(k, r, d)
                                                                      : solve_cg(k, r, d, options);
    };
    // The exact tangent gives quadratic convergence near a stable equilibrium: tried first.
    if (options.linear_solver == StaticLinearSolver::sparse_ldlt)
      solved = solve(free_stiffness(model, result.x, dofs, Linearisation::exact)) && d.dot(r) > 0.0;
    if (!solved) {
      const Eigen::SparseMatrix<double> k =
          free_stiffness(model, result.x, dofs, Linearisation::definite);
      if (shift == 0.0) solved = solve(k) && d.dot(r) > 0.0;
      // Mechanisms (e.g. the three-tier shell turning on its radial springs, which have no
      // stiffness across them at rest) make K singular. Shift by μM, a pseudo time step of size
      // 1/√μ: still a descent direction, and the shift does not move the solution.
      const double k_scale = k.diagonal().cwiseAbs().mean();
      const double m_scale = free_mass.mean();
      double trial_shift = shift > 0.0 ? std::max(shift / 100.0, 1e-10) : 1e-10;
      for (; !solved && trial_shift <= 1.0; trial_shift *= 100.0) {
        Eigen::SparseMatrix<double> shifted = k;
        for (int j = 0; j < n_free; ++j)
          shifted.coeffRef(j, j) += trial_shift * k_scale / m_scale * free_mass[j];
        solved = solve(shifted) && d.dot(r) > 0.0;
        if (solved) shift = trial_shift;
      }
      if (!solved) shift = 0.0;
    }
    if (!solved)
      throw ModelError("static equilibrium: tangent stiffness is singular at Newton iteration " +
                       std::to_string(iteration) +
                       " (free nodes not supported? fix nodes or add anchors)");

    // Armijo backtracking on U, whose gradient is -f: U(x + αd) <= U(x) - 1e-4 α d·r.
    const double energy = model.potential_energy(result.x);
    const double slope = d.dot(r);
    double alpha = 1.0;
    Eigen::VectorXd trial = result.x;
    for (int halving = 0; halving < 40; ++halving) {
      trial = result.x;
      for (int k = 0; k < n_free; ++k)
        trial[dofs.full_index[k]] += alpha * d[k];
      const double trial_energy = model.potential_energy(trial);
      // Near convergence the energy change drowns in round-off; accept full steps there.
      if (trial_energy <= energy - 1e-4 * alpha * slope ||
          std::abs(trial_energy - energy) <= 1e-13 * std::abs(energy) + 1e-300)
        break;
      alpha *= 0.5;
    }
    result.x = trial;
    r = free_residual(result.x);
    result.residual_norm = r.norm();
  }
  if (result.residual_norm <= target) result.converged = true;
  return result;
}

}  // namespace msfem::massspring
