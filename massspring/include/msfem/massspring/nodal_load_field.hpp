#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "msfem/massspring/force_model.hpp"

namespace msfem::massspring {

class MechanicalSystem;

/// Gravity and constant nodal loads as one force field: f_i = m_i g + F_i, U = -Σ f_i·x_i. It
/// keeps references to the masses, g and F it is built over, so loads changed there act at the
/// next call: a MassSpringModel's second field is the one over its own (after its springs).
/// Its energy is one term per node, so the static solver relaxes it with each node.
class NodalLoadField : public ForceField {
 public:
  /// `masses` (n, kg), `gravity` (m/s²) and `forces` (n x 3, N) must outlive the field.
  NodalLoadField(const Eigen::VectorXd& masses, const Eigen::Vector3d& gravity,
                 const Eigen::MatrixX3d& forces);

  /// Node `node`'s load, m_i g + F_i.
  Eigen::Vector3d load(int node) const {
    return (*masses_)[node] * *gravity_ + forces_->row(node).transpose();
  }

  const std::vector<int>& nodes() const override { return nodes_; }
  std::string name() const override { return "nodal loads"; }
  bool nodewise() const override { return true; }
  double add_node_term(int node, const Eigen::Vector3d& p, Eigen::Vector3d& f,
                       Eigen::Matrix3d& k) const override;

  int num_dofs() const override { return 3 * static_cast<int>(nodes_.size()); }
  void add_force(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                 Eigen::VectorXd& f) const override;
  double potential_energy(const Eigen::VectorXd& x) const override;
  // Constant forces: every derivative is zero.
  void add_dfdx_product(const Eigen::VectorXd&, const Eigen::VectorXd&, const Eigen::VectorXd&,
                        Eigen::VectorXd&, Linearisation) const override {}
  void add_dfdv_product(const Eigen::VectorXd&, const Eigen::VectorXd&,
                        Eigen::VectorXd&) const override {}
  void add_dfdx_triplets(const Eigen::VectorXd&, const Eigen::VectorXd&, Triplets&,
                         Linearisation) const override {}
  void add_dfdv_triplets(const Eigen::VectorXd&, Triplets&) const override {}
  void add_diagonal_blocks(const Eigen::VectorXd&, const Eigen::VectorXd&, double, double,
                           std::vector<Eigen::Matrix3d>&, Linearisation) const override {}

 private:
  const Eigen::VectorXd* masses_;
  const Eigen::Vector3d* gravity_;
  const Eigen::MatrixX3d* forces_;
  std::vector<int> nodes_;  ///< every node
};

}  // namespace msfem::massspring
