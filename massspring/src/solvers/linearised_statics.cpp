#include "msfem/massspring/linearised_statics.hpp"

#include <stdexcept>

#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/nodal_load_field.hpp"
#include "msfem/massspring/spring_force_field.hpp"

#include "static_linear.hpp"

namespace msfem::massspring {

LinearisedStatics::LinearisedStatics(
    const MechanicalSystem& model, const std::vector<Eigen::VectorXd>& parts,
    std::function<std::unique_ptr<SparseSpdFactor>()> factorization)
    : model_(model),
      cholesky_(
          std::make_unique<detail::TangentFactor>(factorization ? factorization() : nullptr)) {
  const int n = model.num_dofs();
  const Eigen::VectorXd rest = model.rest_state();
  const Eigen::VectorXd still = Eigen::VectorXd::Zero(n);
  const SpringForceField& springs = spring_field(model, "the linearised statics");
  const ForceField* loads = model.find_field<NodalLoadField>();  // in rest_force_, unweighted
  std::vector<const ForceField*> fields;
  for (const auto& field : model.fields())
    if (field.get() != &springs && field.get() != loads) fields.push_back(field.get());
  field_rest_force_.resize(parts.size() + fields.size());
  auto jacobian = [&](const ForceField& part) {
    Triplets t;
    part.add_dfdx_triplets(rest, still, t, Linearisation::exact);
    Eigen::SparseMatrix<double> j(n, n);
    j.setFromTriplets(t.begin(), t.end());
    jacobians_.push_back(j);
  };
  for (std::size_t p = 0; p < parts.size(); ++p) {
    SpringNetwork part = springs.network();
    if (parts[p].size() != part.num_springs())
      throw ModelError("linearised statics: part " + std::to_string(p) + " has " +
                       std::to_string(parts[p].size()) + " stiffnesses for " +
                       std::to_string(part.num_springs()) + " springs");
    part.stiffness = parts[p];
    if (p > 0) part.anchor_stiffness.setZero();  // the anchors belong to part 0
    jacobian(SpringForceField(part));
  }
  for (std::size_t q = 0; q < fields.size(); ++q) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
    fields[q]->add_force(rest, still, f);
    if (!f.isZero(0.0)) field_rest_force_[parts.size() + q] = f;
    jacobian(*fields[q]);
  }
  std::vector<Eigen::Triplet<double>> s;
  prescribed_ = Eigen::VectorXd::Zero(n);
  for (int i = 0, row = 0; i < model.num_nodes(); ++i) {
    if (model.is_constrained(i)) {
      prescribed_.segment<3>(3 * i) = model.constrained_target(i) - rest.segment<3>(3 * i);
      continue;
    }
    for (int c = 0; c < 3; ++c)
      s.emplace_back(row++, 3 * i + c, 1.0);
  }
  select_.resize(static_cast<Eigen::Index>(s.size()), n);
  select_.setFromTriplets(s.begin(), s.end());
  // Springs exert nothing at rest: what is left is gravity and the external forces.
  rest_force_ = model.force(rest, Eigen::VectorXd::Zero(n));
  // Restricted once, so that a new set of weights costs sums and one factorisation.
  for (const auto& j : jacobians_) {
    free_stiffness_.push_back(-(select_ * j * select_.transpose()));
    free_load_.push_back(select_ * (j * prescribed_));
  }
}

LinearisedStatics::Solution LinearisedStatics::solve(const std::vector<double>& weights,
                                                     const std::vector<int>& patch) {
  if (weights.size() != jacobians_.size())
    throw std::invalid_argument("LinearisedStatics: one weight per part is needed");
  // f(u) = f_rest + J u = 0 on the free dofs, u = prescribed on the others.
  Eigen::SparseMatrix<double> k = weights[0] * free_stiffness_[0];
  Eigen::VectorXd rhs = select_ * rest_force_ + weights[0] * free_load_[0];
  for (std::size_t p = 1; p < jacobians_.size(); ++p) {
    k += weights[p] * free_stiffness_[p];
    rhs += weights[p] * free_load_[p];
    // rest_force_ holds each field's rest force at weight 1.
    if (field_rest_force_[p].size() > 0)
      rhs += (weights[p] - 1.0) * (select_ * field_rest_force_[p]);
  }
  if (!cholesky_->factorize(k))
    throw std::runtime_error(
        "the spring model linearised at rest is not positive definite (a mechanism that only "
        "the deformed state stiffens): use calibration/model = nonlinear");
  const Eigen::VectorXd u = prescribed_ + select_.transpose() * cholesky_->solve(rhs);
  if (!u.allFinite()) throw std::runtime_error("linearised statics: non-finite displacement");
  // A mechanism the factorisation let through (pivots tiny but positive) shows as free nodes moving
  // far more than anything pushes them.
  const double pushed = prescribed_.cwiseAbs().maxCoeff();
  if (pushed > 0 && u.cwiseAbs().maxCoeff() > 100.0 * pushed)
    throw std::runtime_error(
        "the spring model linearised at rest has a mechanism (free nodes move " +
        std::to_string(u.cwiseAbs().maxCoeff() / pushed) +
        " times the prescribed displacement): it needs the deformed state to stiffen it");
  Solution s;
  const auto& surface = spring_field(model_, "the linearised statics").network().surface_nodes;
  s.surface_displacement.resize(static_cast<Eigen::Index>(surface.size()), 3);
  for (std::size_t v = 0; v < surface.size(); ++v)
    s.surface_displacement.row(static_cast<Eigen::Index>(v)) =
        u.segment<3>(3 * surface[v]).transpose();
  // Only the patch rows of J u are needed: J is symmetric, so row i of J is column i.
  for (int node : patch)
    for (int c = 0; c < 3; ++c) {
      double f = rest_force_[3 * node + c];
      for (std::size_t p = 0; p < jacobians_.size(); ++p) {
        f += weights[p] * jacobians_[p].col(3 * node + c).dot(u);
        if (field_rest_force_[p].size() > 0)
          f += (weights[p] - 1.0) * field_rest_force_[p][3 * node + c];
      }
      s.patch_force[c] += f;
    }
  return s;
}

LinearisedStatics::~LinearisedStatics() = default;

}  // namespace msfem::massspring
