#pragma once

#include "msfem/massspring/force_model.hpp"
#include "msfem/massspring/spring_network.hpp"

namespace msfem::massspring {

/// The springs, dampers, anchors and node dampers of a SpringNetwork as one force field on all its
/// nodes. It keeps a reference to the network, so parameters changed there (stiffness per group,
/// damping) act at the next call: a MassSpringModel's first field is the one over its own network.
///
/// Spring s between nodes i and j, d = x_j - x_i, l = |d|, n = d / l, w = v_j - v_i:
///   f_i = k (l - l0) n + c (n·w) n,   f_j = -f_i,   U = ½ k (l - l0)²
/// (Hooke spring with a damper along the spring). Anchor a on node i at point p:
///   f_i = -k_a (x_i - p) - c_a v_i,   U = ½ k_a |x_i - p|².  Node damping: f_i = -c_i v_i.
class SpringForceField : public ForceField {
 public:
  explicit SpringForceField(const SpringNetwork& network);

  const std::vector<int>& nodes() const override { return nodes_; }
  std::string name() const override { return "springs"; }
  void add_diagonal_blocks(const Eigen::VectorXd& x, const Eigen::VectorXd& v, double cx, double cv,
                           std::vector<Eigen::Matrix3d>& blocks, Linearisation mode) const override;

  int num_dofs() const override { return 3 * network_->num_nodes(); }
  void add_force(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                 Eigen::VectorXd& f) const override;
  double potential_energy(const Eigen::VectorXd& x) const override;
  void add_dfdx_product(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                        const Eigen::VectorXd& dx, Eigen::VectorXd& df,
                        Linearisation mode = Linearisation::exact) const override;
  void add_dfdv_product(const Eigen::VectorXd& x, const Eigen::VectorXd& dv,
                        Eigen::VectorXd& df) const override;
  void add_dfdx_triplets(const Eigen::VectorXd& x, const Eigen::VectorXd& v, Triplets& triplets,
                         Linearisation mode = Linearisation::exact) const override;
  void add_dfdv_triplets(const Eigen::VectorXd& x, Triplets& triplets) const override;

  /// The 3x3 block A = ∂f_i/∂x_j of spring s (∂f_i/∂x_i = -A, ∂f_j/∂x_j = -A, ∂f_j/∂x_i = A).
  Eigen::Matrix3d spring_dfdx_block(int s, const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                    Linearisation mode) const;

  const SpringNetwork& network() const { return *network_; }

 private:
  const SpringNetwork* network_;
  std::vector<int> nodes_;  ///< every node: a spring network's dampers act on each
};

class MechanicalSystem;
/// The springs of `system`, its first SpringForceField; throws ModelError saying that `who` needs
/// a spring network when it has none.
const SpringForceField& spring_field(const MechanicalSystem& system, const std::string& who);

}  // namespace msfem::massspring
