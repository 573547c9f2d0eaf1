// Newton's method with line search for the static equilibrium of a spring network.

#include "msfem/massspring/static_solver.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "msfem/massspring/errors.hpp"
#include "static_linear.hpp"

namespace msfem::massspring {
namespace {

using detail::FreeDofs;
using detail::KrylovOutcome;
using SparseMatrix = Eigen::SparseMatrix<double>;

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

// Finds Newton directions; keeps the last factorisation (and its symbolic analysis) between
// iterations, where it preconditions CG on the next tangent.
class DirectionFinder {
 public:
  DirectionFinder(const MassSpringModel& model, const FreeDofs& dofs, const StaticOptions& options)
      : model_(model), dofs_(dofs), options_(options), free_mass_(dofs.gather(model.mass_per_dof())) {}

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
      if (factorized(free_stiffness(model_, x, dofs_, Linearisation::exact, tension_), r, d)) {
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
    const SparseMatrix k = free_stiffness(model_, x, dofs_, Linearisation::definite, tension_);
    auto solve = [&](const SparseMatrix& matrix) {
      return ldlt ? factorized(matrix, r, d) : solve_jacobi_cg(matrix, r, d, options_) && d.dot(r) > 0.0;
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
  void set_tension(const Eigen::VectorXd* tension) { tension_ = tension; }
  bool has_factor() const { return factor_.valid(); }
  Eigen::VectorXd factor_solve(const Eigen::VectorXd& r) const { return factor_.solve(r); }

 private:
  bool factorized(const SparseMatrix& k, const Eigen::VectorXd& r, Eigen::VectorXd& d) {
    if (!factor_.factorize(k)) return false;
    d = factor_.solve(r);
    return d.allFinite() && d.dot(r) > 0.0;
  }

  KrylovOutcome preconditioned(const Eigen::VectorXd& x, Linearisation mode,
                               const Eigen::VectorXd& r, double tolerance, Eigen::VectorXd& d,
                               StaticIteration& record) {
    const detail::TangentOperator k(model_, dofs_, x, mode, tension_);
    int iterations = 0;
    const KrylovOutcome outcome = detail::preconditioned_cg(
        [&](const Eigen::VectorXd& v) { return k * v; }, factor_, r, tolerance,
        options_.max_preconditioned_iterations, d, iterations);
    record.preconditioned_iterations += iterations;
    return outcome;
  }

  const MassSpringModel& model_;
  const FreeDofs& dofs_;
  const StaticOptions& options_;
  const Eigen::VectorXd free_mass_;
  detail::TangentFactor factor_;
  double shift_ = 0.0;  // last μ that made the shifted tangent positive definite
  const Eigen::VectorXd* tension_ = nullptr;
};

// |f_free| of the applied loads (gravity, external forces) and of the initial state, whose
// larger is the scale of the problem: neither depends on where Newton starts.
double reference_norm(const MassSpringModel& model, const FreeDofs& dofs) {
  double load_norm_squared = 0.0;
  for (int i = 0; i < model.num_nodes(); ++i)
    if (!model.is_constrained(i))
      load_norm_squared += (model.network().masses[i] * model.gravity() +
                            model.external_forces().row(i).transpose())
                               .squaredNorm();
  const Eigen::VectorXd x0 = model.initial_state();
  const double initial = dofs.gather(model.force(x0, Eigen::VectorXd::Zero(x0.size()))).norm();
  return std::max(std::sqrt(load_norm_squared), initial);
}


struct LineSearchResult {
  double alpha = 1.0;
  Eigen::VectorXd x, r;
  int evaluations = 0;
};

// Line search on U(x + αd), whose slope is -f(x + αd)·d: sufficient decrease (Armijo) and a
// strong-Wolfe curvature test |U'(α)| <= c2 |U'(0)|, reached by backtracking when the step is too
// long and by secant extrapolation when it is too short. Too short is the common case on the
// brain: near-mechanisms (a floppy shell, folded tier-2 springs only microns long) make U grow
// faster than quadratically along the soft modes, where a full Newton step covers a fraction of
// the way and plain backtracking then crawls at Newton's linear rate.
LineSearchResult line_search(const MassSpringModel& model, const FreeDofs& dofs,
                             const Eigen::VectorXd& x, const Eigen::VectorXd& r,
                             const Eigen::VectorXd& d, double target) {
  static const double c2 = std::getenv("MSFEM_C2") ? std::atof(std::getenv("MSFEM_C2")) : 0.1;
  static const int max_trials = std::getenv("MSFEM_TRIALS") ? std::atoi(std::getenv("MSFEM_TRIALS")) : 8;
  constexpr double c1 = 1e-4;
  struct Point {
    double alpha, energy, slope;
  };
  const double energy0 = model.potential_energy(x);
  const double slope0 = -d.dot(r);
  // Near convergence the energy change drowns in round-off; such steps count as decreasing.
  const double noise = 1e-13 * std::abs(energy0) + 1e-300;
  LineSearchResult out;
  auto evaluate = [&](double alpha, Eigen::VectorXd& xa, Eigen::VectorXd& ra) {
    xa = x;
    dofs.scatter_add(d, alpha, xa);
    ra = dofs.gather(model.force(xa, Eigen::VectorXd::Zero(xa.size())));
    ++out.evaluations;
    return Point{alpha, model.potential_energy(xa), -d.dot(ra)};
  };
  Point lo{0.0, energy0, slope0};
  Point hi{0.0, 0.0, 0.0};
  bool have_hi = false, have_best = false;
  Point previous = lo;
  double alpha = 1.0;
  Eigen::VectorXd xa, ra;
  for (int trial = 0; trial < max_trials; ++trial) {
    const Point p = evaluate(alpha, xa, ra);
    const bool decreased = p.energy <= energy0 + c1 * p.alpha * slope0 || std::abs(p.energy - energy0) <= noise;
    if (decreased && (p.energy <= lo.energy + noise)) {
      out.alpha = p.alpha;
      out.x = xa;
      out.r = ra;
      have_best = true;
      if (std::abs(p.slope) <= c2 * std::abs(slope0) || ra.norm() <= target) return out;
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
    if (have_hi) {
      double next;
      if (hi.slope > 0.0 && hi.energy <= energy0 + noise)  // secant on the slope
        next = lo.alpha - lo.slope * width / (hi.slope - lo.slope);
      else  // minimum of the quadratic through lo (value, slope) and hi (value)
        next = lo.alpha - 0.5 * lo.slope * width * width / (hi.energy - lo.energy - lo.slope * width);
      if (!std::isfinite(next)) next = lo.alpha + 0.5 * width;
      alpha = std::clamp(next, lo.alpha + 0.1 * width, hi.alpha - 0.1 * width);
    } else {
      // Still descending: extrapolate the slope to zero, at least doubling, at most ×4.
      const double next = lo.slope > previous.slope
                              ? lo.alpha - lo.slope * (lo.alpha - previous.alpha) / (lo.slope - previous.slope)
                              : 4.0 * lo.alpha;
      alpha = std::clamp(std::isfinite(next) ? next : 4.0 * lo.alpha, 2.0 * lo.alpha, 4.0 * lo.alpha);
    }
  }
  if (have_best) return out;
  // No decrease found yet: keep halving, as plain Armijo backtracking would.
  for (int halving = 0; halving < 40; ++halving) {
    const Point p = evaluate(alpha, xa, ra);
    if (p.energy <= energy0 + c1 * p.alpha * slope0 || std::abs(p.energy - energy0) <= noise) break;
    alpha *= 0.5;
  }
  out.alpha = alpha;
  out.x = xa;
  out.r = ra;
  return out;
}

// Nonlinear Gauss-Seidel on single nodes (prototype).
struct NodeSprings {
  std::vector<int> start, spring;  // CSR: springs at node
};
NodeSprings node_springs(const SpringNetwork& net) {
  NodeSprings a;
  a.start.assign(net.num_nodes() + 1, 0);
  for (int s = 0; s < net.num_springs(); ++s) { ++a.start[net.springs(s, 0) + 1]; ++a.start[net.springs(s, 1) + 1]; }
  for (int i = 0; i < net.num_nodes(); ++i) a.start[i + 1] += a.start[i];
  a.spring.resize(a.start.back());
  std::vector<int> fill(a.start.begin(), a.start.end() - 1);
  for (int s = 0; s < net.num_springs(); ++s) { a.spring[fill[net.springs(s, 0)]++] = s; a.spring[fill[net.springs(s, 1)]++] = s; }
  return a;
}
// Local energy, force and stiffness of node i's springs (anchors and contact ignored: prototype).
double node_local(const MassSpringModel& model, const NodeSprings& adj, const Eigen::VectorXd& x, int i,
                  const Eigen::Vector3d& xi, Eigen::Vector3d* f, Eigen::Matrix3d* h) {
  const SpringNetwork& net = model.network();
  const Eigen::Vector3d load = net.masses[i] * model.gravity() + model.external_forces().row(i).transpose();
  double e = -load.dot(xi);
  if (f) *f = load;
  if (h) h->setZero();
  for (int q = adj.start[i]; q < adj.start[i + 1]; ++q) {
    const int s = adj.spring[q];
    const int j = net.springs(s, 0) == i ? net.springs(s, 1) : net.springs(s, 0);
    const Eigen::Vector3d d = x.segment<3>(3 * j) - xi;
    const double l = d.norm();
    const double k = net.stiffness[s], stretch = l - net.rest_length[s];
    e += 0.5 * k * stretch * stretch;
    if (!(l > 0.0)) continue;
    const Eigen::Vector3d n = d / l;
    if (f) *f += k * stretch * n;
    if (h) {
      const Eigen::Matrix3d nn = n * n.transpose();
      *h += k * (nn + std::max(stretch / l, 0.0) * (Eigen::Matrix3d::Identity() - nn));
    }
  }
  return e;
}
int relax_nodes(const MassSpringModel& model, const FreeDofs& dofs, const NodeSprings& adj, Eigen::VectorXd& x, const Eigen::VectorXd& r, double fraction, int sweeps) {
  if (model.contact()) return 0;
  std::vector<int> nodes;
  double rmax = 0;
  for (int k = 0; k < dofs.size(); k += 3) rmax = std::max(rmax, r.segment<3>(k).norm());
  for (int k = 0; k < dofs.size(); k += 3) if (r.segment<3>(k).norm() >= fraction * rmax) nodes.push_back(dofs.full_index[k] / 3);
  for (int sweep = 0; sweep < sweeps; ++sweep)
    for (int i : nodes) {
      for (int it = 0; it < 5; ++it) {
        Eigen::Vector3d xi = x.segment<3>(3 * i), f; Eigen::Matrix3d h;
        const double e0 = node_local(model, adj, x, i, xi, &f, &h);
        const Eigen::Vector3d step = h.ldlt().solve(f);
        if (!step.allFinite() || step.dot(f) <= 0) break;
        double a = 1.0; bool ok = false;
        for (int b = 0; b < 20; ++b, a *= 0.5) {
          if (node_local(model, adj, x, i, xi + a * step, nullptr, nullptr) <= e0) { ok = true; break; }
        }
        if (!ok) break;
        x.segment<3>(3 * i) = xi + a * step;
        if (a * step.norm() < 1e-15 * xi.norm()) break;
      }
    }
  return static_cast<int>(nodes.size());
}

}  // namespace

StaticResult solve_static(const MassSpringModel& model, const StaticOptions& options,
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
  auto free_residual = [&](const Eigen::VectorXd& x) {
    return dofs.gather(model.force(x, Eigen::VectorXd::Zero(x.size())));
  };
  Eigen::VectorXd r = free_residual(result.x);
  result.residual_norm = r.norm();
  result.reference_norm = reference_norm(model, dofs);
  if (!(result.reference_norm > 0.0)) {
    result.converged = true;  // unloaded and at rest: already in equilibrium
    return result;
  }
  const double target = options.tolerance * result.reference_norm;
  const bool trace = std::getenv("MSFEM_TRACE") != nullptr;
  const double forcing_power = std::getenv("MSFEM_FORCING") ? std::atof(std::getenv("MSFEM_FORCING")) : 1.0;

  DirectionFinder directions(model, dofs, options);
  static const bool mixed = std::getenv("MSFEM_MIXED") != nullptr;
  const SpringNetwork& net = model.network();
  Eigen::VectorXd tension(net.num_springs());
  for (int s = 0; s < net.num_springs(); ++s)
    tension[s] = net.stiffness[s] * ((result.x.segment<3>(3 * net.springs(s, 1)) - result.x.segment<3>(3 * net.springs(s, 0))).norm() - net.rest_length[s]);
  if (mixed) directions.set_tension(&tension);
  double previous_residual = 0.0, previous_eta = 0.1;
  while (result.residual_norm > target && result.iterations < options.max_iterations) {
    ++result.iterations;
    // Inexact Newton: the linear residual need only be small against |f| (Eisenstat-Walker), and
    // never much below the target, to keep Newton's quadratic convergence.
    const double relative = result.residual_norm / result.reference_norm;
    static const bool ew = std::getenv("MSFEM_EW") != nullptr;
    static const double eta_max = std::getenv("MSFEM_ETAMAX") ? std::atof(std::getenv("MSFEM_ETAMAX")) : 0.5;
    double eta = std::min(0.1, std::pow(relative, forcing_power));
    if (ew) {
      if (previous_residual > 0.0) {
        const double ratio = result.residual_norm / previous_residual;
        double next = 0.9 * ratio * ratio;
        if (0.9 * previous_eta * previous_eta > 0.1) next = std::max(next, 0.9 * previous_eta * previous_eta);
        eta = std::min(next, eta_max);
      } else {
        eta = 0.1;
      }
      previous_eta = eta;
      previous_residual = result.residual_norm;
    }
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
    if (trace) { int k; d.cwiseAbs().maxCoeff(&k); int node = dofs.full_index[k] / 3;
      std::fprintf(stderr, "   |d|inf %.3e node %d at (%.4f %.4f %.4f) |d|2 %.3e\n", d.cwiseAbs().maxCoeff(), node, model.network().rest_positions(node,0), model.network().rest_positions(node,1), model.network().rest_positions(node,2), d.norm()); }

    const LineSearchResult ls = line_search(model, dofs, result.x, r, d, target);
    if (mixed) {
      Eigen::VectorXd full_d = Eigen::VectorXd::Zero(result.x.size());
      dofs.scatter_add(d, 1.0, full_d);
      for (int s = 0; s < net.num_springs(); ++s) {
        const int i = net.springs(s, 0), j = net.springs(s, 1);
        const Eigen::Vector3d e = result.x.segment<3>(3 * j) - result.x.segment<3>(3 * i);
        const double l = e.norm();
        if (!(l > 0.0)) continue;
        const double predicted = net.stiffness[s] * (l - net.rest_length[s] + e.dot(full_d.segment<3>(3 * j) - full_d.segment<3>(3 * i)) / l);
        tension[s] += ls.alpha * (predicted - tension[s]);
      }
    }
    const double alpha = ls.alpha;
    const bool use_soc = false;
    result.x = ls.x;
    r = ls.r;
    static const double relax_fraction = std::getenv("MSFEM_RELAX") ? std::atof(std::getenv("MSFEM_RELAX")) : -1.0;
    static const int relax_sweeps = std::getenv("MSFEM_SWEEPS") ? std::atoi(std::getenv("MSFEM_SWEEPS")) : 2;
    if (relax_fraction >= 0.0 && r.norm() > target) {
      static NodeSprings adj;
      if (adj.start.empty()) adj = node_springs(net);
      const int relaxed = relax_nodes(model, dofs, adj, result.x, r, relax_fraction, relax_sweeps);
      const double before = r.norm();
      r = free_residual(result.x);
      if (trace) std::fprintf(stderr, "   relaxed %d nodes: |r| %.3e -> %.3e\n", relaxed, before, r.norm());
    }
    result.residual_norm = r.norm();
    record.residual_norm = result.residual_norm;
    record.step_length = alpha;
    result.history.push_back(record);
    if (std::getenv("MSFEM_DUMP") && std::atoi(std::getenv("MSFEM_DUMP")) == result.iterations) {
      FILE* fd = std::fopen("/tmp/sdrv/xdump.bin", "wb"); std::fwrite(result.x.data(), 8, result.x.size(), fd); std::fclose(fd); }
    if (trace) {
      int kmax; Eigen::VectorXd rn(dofs.size() / 3);
      for (int q = 0; q < rn.size(); ++q) rn[q] = r.segment<3>(3 * q).norm();
      rn.maxCoeff(&kmax); const int node = dofs.full_index[3 * kmax] / 3;
      double stiff = 0; for (int s = 0; s < net.num_springs(); ++s) if (net.springs(s,0) == node || net.springs(s,1) == node) stiff = std::max(stiff, net.stiffness[s]);
      std::fprintf(stderr, "   max |r_i| %.3e (%.0f%%) node %d kmax %.3g\n", rn[kmax], 100 * rn[kmax] / r.norm(), node, stiff);
    }
    if (trace)
      std::fprintf(stderr, "it %3d |r| %.3e alpha %.3e soc %d step %d shift %.1e pcg %d fact %d\n",
                   result.iterations, result.residual_norm, alpha, (int)use_soc, static_cast<int>(record.step),
                   record.shift, record.preconditioned_iterations, directions.factorizations());
  }
  result.factorizations = directions.factorizations();
  result.converged = result.residual_norm <= target;
  return result;
}

}  // namespace msfem::massspring
