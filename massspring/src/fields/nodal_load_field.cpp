#include "msfem/massspring/nodal_load_field.hpp"

#include <numeric>

#include "msfem/massspring/errors.hpp"

namespace msfem::massspring {

NodalLoadField::NodalLoadField(const Eigen::VectorXd& masses, const Eigen::Vector3d& gravity,
                               const Eigen::MatrixX3d& forces)
    : masses_(&masses),
      gravity_(&gravity),
      forces_(&forces),
      nodes_(static_cast<std::size_t>(masses.size())) {
  if (forces.rows() != masses.size())
    throw ModelError("nodal loads: " + std::to_string(forces.rows()) + " forces for " +
                     std::to_string(masses.size()) + " nodes");
  std::iota(nodes_.begin(), nodes_.end(), 0);
}

double NodalLoadField::add_node_term(int node, const Eigen::Vector3d& p, Eigen::Vector3d& f,
                                     Eigen::Matrix3d&) const {
  const Eigen::Vector3d l = load(node);
  f += l;
  return -l.dot(p);
}

void NodalLoadField::add_force(const Eigen::VectorXd&, const Eigen::VectorXd&,
                               Eigen::VectorXd& f) const {
  for (int i = 0; i < static_cast<int>(nodes_.size()); ++i)
    f.segment<3>(3 * i) += load(i);
}

double NodalLoadField::potential_energy(const Eigen::VectorXd& x) const {
  double energy = 0.0;
  for (int i = 0; i < static_cast<int>(nodes_.size()); ++i)
    energy -= load(i).dot(x.segment<3>(3 * i));
  return energy;
}

}  // namespace msfem::massspring
