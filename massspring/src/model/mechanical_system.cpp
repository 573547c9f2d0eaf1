#include "msfem/massspring/mechanical_system.hpp"

namespace msfem::massspring {

std::string MechanicalSystem::field_names() const {
  std::string names;
  for (const auto& f : fields())
    names += (names.empty() ? "" : ", ") + f->name();
  return names;
}

void MechanicalSystem::add_force(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                 Eigen::VectorXd& f) const {
  for (const auto& field : fields())
    field->add_force(x, v, f);
}

double MechanicalSystem::potential_energy(const Eigen::VectorXd& x) const {
  double energy = 0.0;
  for (const auto& field : fields())
    energy += field->potential_energy(x);
  return energy;
}

void MechanicalSystem::add_dfdx_product(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                        const Eigen::VectorXd& dx, Eigen::VectorXd& df,
                                        Linearisation mode) const {
  for (const auto& field : fields())
    field->add_dfdx_product(x, v, dx, df, mode);
}

void MechanicalSystem::add_dfdv_product(const Eigen::VectorXd& x, const Eigen::VectorXd& dv,
                                        Eigen::VectorXd& df) const {
  for (const auto& field : fields())
    field->add_dfdv_product(x, dv, df);
}

void MechanicalSystem::add_dfdx_triplets(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                         Triplets& triplets, Linearisation mode) const {
  for (const auto& field : fields())
    field->add_dfdx_triplets(x, v, triplets, mode);
}

void MechanicalSystem::add_dfdv_triplets(const Eigen::VectorXd& x, Triplets& triplets) const {
  for (const auto& field : fields())
    field->add_dfdv_triplets(x, triplets);
}

std::vector<int> MechanicalSystem::constrained_nodes() const {
  std::vector<int> nodes;
  for (int i = 0; i < num_nodes(); ++i)
    if (is_constrained(i)) nodes.push_back(i);
  return nodes;
}

Eigen::VectorXd MechanicalSystem::initial_state() const {
  Eigen::VectorXd x = rest_state();
  Eigen::VectorXd v = Eigen::VectorXd::Zero(x.size());
  enforce_constraints(x, v);
  return x;
}

Eigen::VectorXd MechanicalSystem::mass_per_dof() const {
  Eigen::VectorXd m(num_dofs());
  for (int i = 0; i < num_nodes(); ++i)
    m.segment<3>(3 * i).setConstant(masses()[i]);
  return m;
}

void MechanicalSystem::enforce_constraints(Eigen::VectorXd& x, Eigen::VectorXd& v) const {
  for (int i = 0; i < num_nodes(); ++i) {
    if (!is_constrained(i)) continue;
    x.segment<3>(3 * i) = constrained_target(i);
    v.segment<3>(3 * i).setZero();
  }
}

void MechanicalSystem::zero_constrained(Eigen::VectorXd& vector) const {
  for (int i = 0; i < num_nodes(); ++i)
    if (is_constrained(i)) vector.segment<3>(3 * i).setZero();
}

Eigen::VectorXd MechanicalSystem::acceleration(const Eigen::VectorXd& x,
                                               const Eigen::VectorXd& v) const {
  Eigen::VectorXd a = Eigen::VectorXd::Zero(num_dofs());
  add_force(x, v, a);
  const Eigen::VectorXd& m = masses();
  for (int i = 0; i < num_nodes(); ++i)
    a.segment<3>(3 * i) *= is_constrained(i) ? 0.0 : 1.0 / m[i];
  return a;
}

double MechanicalSystem::kinetic_energy(const Eigen::VectorXd& v) const {
  const Eigen::VectorXd& m = masses();
  double energy = 0.0;
  for (int i = 0; i < num_nodes(); ++i)
    energy += 0.5 * m[i] * v.segment<3>(3 * i).squaredNorm();
  return energy;
}

}  // namespace msfem::massspring
