#include "static_linear.hpp"

#include <algorithm>
#include <cmath>

namespace msfem::massspring::detail {

FreeDofs::FreeDofs(const MechanicalSystem& model) {
  free_index.assign(model.num_dofs(), -1);
  for (int i = 0; i < model.num_nodes(); ++i) {
    if (model.is_constrained(i)) continue;
    for (int c = 0; c < 3; ++c) {
      free_index[3 * i + c] = static_cast<int>(full_index.size());
      full_index.push_back(3 * i + c);
    }
  }
}

Eigen::VectorXd FreeDofs::gather(const Eigen::VectorXd& full) const {
  Eigen::VectorXd free(size());
  for (int k = 0; k < size(); ++k)
    free[k] = full[full_index[k]];
  return free;
}

void FreeDofs::scatter_add(const Eigen::VectorXd& free, double scale, Eigen::VectorXd& full) const {
  for (int k = 0; k < size(); ++k)
    full[full_index[k]] += scale * free[k];
}

Eigen::SparseMatrix<double> free_stiffness(const MechanicalSystem& model, const Eigen::VectorXd& x,
                                           const FreeDofs& dofs, Linearisation mode) {
  Triplets all;
  model.add_dfdx_triplets(x, Eigen::VectorXd::Zero(x.size()), all, mode);
  Triplets free;
  free.reserve(all.size() + 3 * dofs.size());
  for (const auto& t : all) {
    const int r = dofs.free_index[t.row()];
    const int c = dofs.free_index[t.col()];
    if (r >= 0 && c >= 0) free.emplace_back(r, c, -t.value());
  }
  // Explicit zeros keep the diagonal blocks in the pattern whatever the contact state.
  for (int k = 0; k < dofs.size(); k += 3)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        free.emplace_back(k + r, k + c, 0.0);
  Eigen::SparseMatrix<double> k(dofs.size(), dofs.size());
  k.setFromTriplets(free.begin(), free.end());
  return k;
}

TangentOperator::TangentOperator(const MechanicalSystem& model, const FreeDofs& dofs,
                                 const Eigen::VectorXd& x, Linearisation mode)
    : model_(model),
      dofs_(dofs),
      x_(x),
      mode_(mode),
      full_dx_(Eigen::VectorXd::Zero(x.size())),
      full_df_(x.size()) {}

Eigen::VectorXd TangentOperator::operator*(const Eigen::VectorXd& v) const {
  for (int k = 0; k < dofs_.size(); ++k)
    full_dx_[dofs_.full_index[k]] = v[k];
  full_df_.setZero();
  // Velocities are zero in statics, so the damping terms of ∂f/∂x vanish.
  model_.add_dfdx_product(x_, Eigen::VectorXd::Zero(x_.size()), full_dx_, full_df_, mode_);
  return -dofs_.gather(full_df_);
}

bool TangentFactor::same_pattern(const Eigen::SparseMatrix<double>& k) const {
  const auto n_outer = static_cast<std::size_t>(k.outerSize()) + 1;
  const auto n_inner = static_cast<std::size_t>(k.nonZeros());
  return outer_.size() == n_outer && inner_.size() == n_inner &&
         std::equal(outer_.begin(), outer_.end(), k.outerIndexPtr()) &&
         std::equal(inner_.begin(), inner_.end(), k.innerIndexPtr());
}

bool TangentFactor::factorize(const Eigen::SparseMatrix<double>& k) {
  if (!analysed_ || !same_pattern(k)) {
    // The ordering costs as much as a tenth of a factorisation on the brain; the pattern never
    // changes within a solve.
    if (plugged_)
      plugged_->analyze(k);
    else
      ldlt_.analyzePattern(k);
    outer_.assign(k.outerIndexPtr(), k.outerIndexPtr() + k.outerSize() + 1);
    inner_.assign(k.innerIndexPtr(), k.innerIndexPtr() + k.nonZeros());
    analysed_ = true;
  }
  ++factorizations_;
  valid_ = false;
  if (plugged_) {
    valid_ = plugged_->factorize(k);
    return valid_;
  }
  ldlt_.factorize(k);
  if (ldlt_.info() != Eigen::Success) return false;
  const Eigen::VectorXd pivots = ldlt_.vectorD();
  valid_ = pivots.allFinite() && (pivots.array() > 1e-12 * pivots.cwiseAbs().maxCoeff()).all();
  return valid_;
}

KrylovOutcome preconditioned_cg(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& k,
                                const TangentFactor& factor, const Eigen::VectorXd& r,
                                double absolute_tolerance, int max_iterations, Eigen::VectorXd& d,
                                int& iterations) {
  d = Eigen::VectorXd::Zero(r.size());
  Eigen::VectorXd residual = r;
  Eigen::VectorXd z = factor.solve(residual);
  Eigen::VectorXd p = z;
  double rz = residual.dot(z);
  for (iterations = 0; residual.norm() > absolute_tolerance; ++iterations) {
    if (iterations >= max_iterations || !(rz > 0.0) || !std::isfinite(rz))
      return KrylovOutcome::too_many_iterations;
    const Eigen::VectorXd kp = k(p);
    const double pkp = p.dot(kp);
    if (!(pkp > 0.0)) return KrylovOutcome::negative_curvature;
    const double alpha = rz / pkp;
    d += alpha * p;
    residual -= alpha * kp;
    z = factor.solve(residual);
    const double rz_next = residual.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  return d.allFinite() ? KrylovOutcome::converged : KrylovOutcome::too_many_iterations;
}

}  // namespace msfem::massspring::detail
