#include "msfem/massspring/modal_damping.hpp"

#include <Eigen/SparseCholesky>
#include <cmath>
#include <stdexcept>

#include "msfem/massspring/spring_force_field.hpp"
#include "static_linear.hpp"

namespace msfem::massspring {
namespace {

// −(triplets) restricted to the free dofs: the stiffness K = −∂f/∂x or the damping C = −∂f/∂v.
Eigen::SparseMatrix<double> restricted(const detail::FreeDofs& dofs, const Triplets& all) {
  Triplets free;
  for (const auto& t : all) {
    const int r = dofs.free_index[t.row()], c = dofs.free_index[t.col()];
    if (r >= 0 && c >= 0) free.emplace_back(r, c, -t.value());
  }
  Eigen::SparseMatrix<double> a(dofs.size(), dofs.size());
  a.setFromTriplets(free.begin(), free.end());
  return a;
}

}  // namespace

Eigen::VectorXd damping_for_ratio(const SpringNetwork& network, double ratio) {
  Eigen::VectorXd d(network.num_springs());
  for (int s = 0; s < network.num_springs(); ++s) {
    const double ma = network.masses[network.springs(s, 0)];
    const double mb = network.masses[network.springs(s, 1)];
    d[s] = 2.0 * ratio * std::sqrt(network.stiffness[s] * ma * mb / (ma + mb));
  }
  return d;
}

DampingFit fit_damping(const MechanicalSystem& model, const Eigen::VectorXd& x, double target,
                       const Eigen::VectorXd& shape) {
  const detail::FreeDofs dofs(model);
  const int n = static_cast<int>(dofs.full_index.size());
  if (n == 0) throw std::invalid_argument("fit_damping: every node is constrained");
  Triplets kt;
  model.add_dfdx_triplets(x, Eigen::VectorXd::Zero(x.size()), kt, Linearisation::exact);
  Eigen::SparseMatrix<double> k = restricted(dofs, kt);
  const Eigen::VectorXd all_mass = model.mass_per_dof();
  Eigen::VectorXd mass(n);
  for (int i = 0; i < n; ++i)
    mass[i] = all_mass[dofs.full_index[i]];
  Eigen::VectorXd v(n);
  double omega2 = 0;
  if (shape.size() == model.num_dofs()) {
    for (int i = 0; i < n; ++i)
      v[i] = shape[dofs.full_index[i]];
    const double norm = std::sqrt(v.dot(mass.cwiseProduct(v)));
    if (!(norm > 0)) throw std::invalid_argument("fit_damping: the mode shape is zero");
    v /= norm;
    omega2 = v.dot(k * v);
  } else {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(k);
    if (ldlt.info() != Eigen::Success || (ldlt.vectorD().array() <= 0).any()) {
      kt.clear();
      model.add_dfdx_triplets(x, Eigen::VectorXd::Zero(x.size()), kt, Linearisation::definite);
      k = restricted(dofs, kt);
      ldlt.compute(k);
      if (ldlt.info() != Eigen::Success)
        throw std::runtime_error("fit_damping: the stiffness at equilibrium is singular");
    }
    // Inverse iteration converges to the mode of the smallest ω² = vᵀKv / vᵀMv.
    v.setOnes();
    for (int it = 0; it < 500; ++it) {
      Eigen::VectorXd y = ldlt.solve(mass.cwiseProduct(v));
      y /= std::sqrt(y.dot(mass.cwiseProduct(y)));
      const double next = y.dot(k * y);
      v = y;
      const bool settled = it > 5 && std::abs(next - omega2) <= 1e-10 * next;
      omega2 = next;
      if (settled) break;
    }
  }
  if (!(omega2 > 0)) throw std::runtime_error("fit_damping: the mode has no stiffness");
  const double omega = std::sqrt(omega2);
  // Modal ratio ζ(r) = vᵀC(r)v / (2ω vᵀMv), with vᵀMv = 1; C is linear in r: ζ(r) = ζ0 + r ζ1.
  const SpringForceField& springs = spring_field(model, "the damping fit");
  auto modal_ratio = [&](double r) {
    SpringNetwork damped = springs.network();
    damped.damping = damping_for_ratio(damped, r);
    Triplets ct;
    SpringForceField(damped).add_dfdv_triplets(x, ct);
    for (const auto& field : model.fields())
      if (field.get() != &springs) field->add_dfdv_triplets(x, ct);
    return v.dot(restricted(dofs, ct) * v) / (2.0 * omega);
  };
  DampingFit f;
  f.target = target;
  f.frequency_hz = omega / (2.0 * M_PI);
  const double zeta0 = modal_ratio(0.0);
  f.modal_ratio_per_unit_r = modal_ratio(1.0) - zeta0;
  // Beyond r = 1000 the dampers would dominate every other mode: not a sensible fit.
  f.reachable = f.modal_ratio_per_unit_r > 1e-3 * std::max(target - zeta0, 0.0) && target >= zeta0;
  f.case_damping_ratio = f.reachable ? (target - zeta0) / f.modal_ratio_per_unit_r : 0.0;
  return f;
}

}  // namespace msfem::massspring
