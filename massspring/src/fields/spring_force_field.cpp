#include "msfem/massspring/spring_force_field.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/mechanical_system.hpp"

namespace msfem::massspring {
namespace {

// Geometry of one spring at the current state.
struct SpringFrame {
  Eigen::Vector3d n;  // unit direction i -> j
  double length;
  bool valid;  // false for a collapsed spring (direction undefined): it then exerts no force
};

SpringFrame frame(const Eigen::VectorXd& x, int i, int j) {
  const Eigen::Vector3d d = x.segment<3>(3 * j) - x.segment<3>(3 * i);
  const double length = d.norm();
  if (!(length > 0.0)) return {Eigen::Vector3d::Zero(), 0.0, false};
  return {d / length, length, true};
}

void add_block(Triplets& triplets, int row_node, int col_node, const Eigen::Matrix3d& block) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      triplets.emplace_back(3 * row_node + r, 3 * col_node + c, block(r, c));
}

// A two-node element's derivative: ∂f_i/∂x_j = block, so ∂f_i/∂x_i = −block (the pair's force
// depends on x_j − x_i alone), and the same for j.
void add_pair_blocks(Triplets& triplets, int i, int j, const Eigen::Matrix3d& block) {
  add_block(triplets, i, j, block);
  add_block(triplets, j, i, block);
  add_block(triplets, i, i, -block);
  add_block(triplets, j, j, -block);
}

// Each anchor's (or node damper's) diagonal: −c on its node's three rows.
void add_node_diagonals(Triplets& triplets, const Eigen::VectorXi& nodes,
                        const Eigen::VectorXd& coefficients) {
  for (Eigen::Index a = 0; a < nodes.size(); ++a)
    for (int r = 0; r < 3; ++r)
      triplets.emplace_back(3 * nodes[a] + r, 3 * nodes[a] + r, -coefficients[a]);
}

}  // namespace

SpringForceField::SpringForceField(const SpringNetwork& network)
    : network_(&network), nodes_(static_cast<std::size_t>(network.num_nodes())) {
  std::iota(nodes_.begin(), nodes_.end(), 0);
}

const SpringForceField& spring_field(const MechanicalSystem& system, const std::string& who) {
  const auto* springs = system.find_field<SpringForceField>();
  if (!springs)
    throw ModelError(who + " needs a spring network: the system's fields (" + system.field_names() +
                     ") hold no springs");
  return *springs;
}

void SpringForceField::add_force(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                 Eigen::VectorXd& f) const {
  const SpringNetwork& net = *network_;
  for (int s = 0; s < net.num_springs(); ++s) {
    const int i = net.springs(s, 0);
    const int j = net.springs(s, 1);
    const SpringFrame fr = frame(x, i, j);
    if (!fr.valid) continue;
    const Eigen::Vector3d w = v.segment<3>(3 * j) - v.segment<3>(3 * i);
    const double magnitude =
        net.stiffness[s] * (fr.length - net.rest_length[s]) + net.damping[s] * fr.n.dot(w);
    f.segment<3>(3 * i) += magnitude * fr.n;
    f.segment<3>(3 * j) -= magnitude * fr.n;
  }
  for (int a = 0; a < net.num_anchors(); ++a) {
    const int i = net.anchor_node[a];
    f.segment<3>(3 * i) -=
        net.anchor_stiffness[a] * (x.segment<3>(3 * i) - net.anchor_point.row(a).transpose()) +
        net.anchor_damping[a] * v.segment<3>(3 * i);
  }
  for (int i = 0; i < net.num_nodes(); ++i)
    f.segment<3>(3 * i) -= net.node_damping[i] * v.segment<3>(3 * i);
}

double SpringForceField::potential_energy(const Eigen::VectorXd& x) const {
  const SpringNetwork& net = *network_;
  double energy = 0.0;
  for (int s = 0; s < net.num_springs(); ++s) {
    const double length =
        (x.segment<3>(3 * net.springs(s, 1)) - x.segment<3>(3 * net.springs(s, 0))).norm();
    const double stretch = length - net.rest_length[s];
    energy += 0.5 * net.stiffness[s] * stretch * stretch;
  }
  for (int a = 0; a < net.num_anchors(); ++a)
    energy +=
        0.5 * net.anchor_stiffness[a] *
        (x.segment<3>(3 * net.anchor_node[a]) - net.anchor_point.row(a).transpose()).squaredNorm();
  return energy;
}

Eigen::Matrix3d SpringForceField::spring_dfdx_block(int s, const Eigen::VectorXd& x,
                                                    const Eigen::VectorXd& v,
                                                    Linearisation mode) const {
  const SpringNetwork& net = *network_;
  const int i = net.springs(s, 0);
  const int j = net.springs(s, 1);
  const SpringFrame fr = frame(x, i, j);
  if (!fr.valid) return Eigen::Matrix3d::Zero();
  const Eigen::Matrix3d nn = fr.n * fr.n.transpose();
  const Eigen::Matrix3d transverse = Eigen::Matrix3d::Identity() - nn;
  // ∂[k (l - l0) n]/∂d = k [ n nᵀ + (1 - l0/l)(I - n nᵀ) ]
  double tension_ratio = 1.0 - net.rest_length[s] / fr.length;
  if (mode == Linearisation::definite) tension_ratio = std::max(tension_ratio, 0.0);
  Eigen::Matrix3d block = net.stiffness[s] * (nn + tension_ratio * transverse);
  if (mode == Linearisation::exact && net.damping[s] != 0.0) {
    // ∂[c (n·w) n]/∂d = (c / l) [ (n·w)(I - n nᵀ) + n wᵀ (I - n nᵀ) ]
    const Eigen::Vector3d w = v.segment<3>(3 * j) - v.segment<3>(3 * i);
    block += (net.damping[s] / fr.length) *
             (fr.n.dot(w) * transverse + fr.n * (transverse * w).transpose());
  }
  return block;
}

void SpringForceField::add_dfdx_product(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                        const Eigen::VectorXd& dx, Eigen::VectorXd& df,
                                        Linearisation mode) const {
  const SpringNetwork& net = *network_;
  for (int s = 0; s < net.num_springs(); ++s) {
    const int i = net.springs(s, 0);
    const int j = net.springs(s, 1);
    const Eigen::Vector3d change =
        spring_dfdx_block(s, x, v, mode) * (dx.segment<3>(3 * j) - dx.segment<3>(3 * i));
    df.segment<3>(3 * i) += change;
    df.segment<3>(3 * j) -= change;
  }
  for (int a = 0; a < net.num_anchors(); ++a) {
    const int i = net.anchor_node[a];
    df.segment<3>(3 * i) -= net.anchor_stiffness[a] * dx.segment<3>(3 * i);
  }
}

void SpringForceField::add_dfdv_product(const Eigen::VectorXd& x, const Eigen::VectorXd& dv,
                                        Eigen::VectorXd& df) const {
  const SpringNetwork& net = *network_;
  for (int s = 0; s < net.num_springs(); ++s) {
    if (net.damping[s] == 0.0) continue;
    const int i = net.springs(s, 0);
    const int j = net.springs(s, 1);
    const SpringFrame fr = frame(x, i, j);
    if (!fr.valid) continue;
    const Eigen::Vector3d change =
        net.damping[s] * fr.n.dot(dv.segment<3>(3 * j) - dv.segment<3>(3 * i)) * fr.n;
    df.segment<3>(3 * i) += change;
    df.segment<3>(3 * j) -= change;
  }
  for (int a = 0; a < net.num_anchors(); ++a) {
    const int i = net.anchor_node[a];
    df.segment<3>(3 * i) -= net.anchor_damping[a] * dv.segment<3>(3 * i);
  }
  for (int i = 0; i < net.num_nodes(); ++i)
    df.segment<3>(3 * i) -= net.node_damping[i] * dv.segment<3>(3 * i);
}

void SpringForceField::add_dfdx_triplets(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                         Triplets& triplets, Linearisation mode) const {
  const SpringNetwork& net = *network_;
  triplets.reserve(triplets.size() + 36 * net.num_springs() + 3 * net.num_anchors());
  for (int s = 0; s < net.num_springs(); ++s) {
    const int i = net.springs(s, 0);
    const int j = net.springs(s, 1);
    const Eigen::Matrix3d block = spring_dfdx_block(s, x, v, mode);
    add_pair_blocks(triplets, i, j, block);
  }
  add_node_diagonals(triplets, net.anchor_node, net.anchor_stiffness);
}

void SpringForceField::add_dfdv_triplets(const Eigen::VectorXd& x, Triplets& triplets) const {
  const SpringNetwork& net = *network_;
  for (int s = 0; s < net.num_springs(); ++s) {
    if (net.damping[s] == 0.0) continue;
    const int i = net.springs(s, 0);
    const int j = net.springs(s, 1);
    const SpringFrame fr = frame(x, i, j);
    if (!fr.valid) continue;
    const Eigen::Matrix3d block = net.damping[s] * fr.n * fr.n.transpose();
    add_pair_blocks(triplets, i, j, block);
  }
  add_node_diagonals(triplets, net.anchor_node, net.anchor_damping);
  for (int i = 0; i < net.num_nodes(); ++i)
    for (int r = 0; r < 3; ++r)
      triplets.emplace_back(3 * i + r, 3 * i + r, -net.node_damping[i]);
}

void SpringForceField::add_diagonal_blocks(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                                           double cx, double cv,
                                           std::vector<Eigen::Matrix3d>& blocks,
                                           Linearisation mode) const {
  const SpringNetwork& net = *network_;
  for (int s = 0; s < net.num_springs(); ++s) {
    const int i = net.springs(s, 0);
    const int j = net.springs(s, 1);
    Eigen::Matrix3d block = cx * spring_dfdx_block(s, x, v, mode);
    const SpringFrame fr = frame(x, i, j);
    if (fr.valid && net.damping[s] != 0.0) block += cv * net.damping[s] * fr.n * fr.n.transpose();
    blocks[static_cast<std::size_t>(i)] -= block;  // ∂f_i/∂x_i = -A
    blocks[static_cast<std::size_t>(j)] -= block;
  }
  for (int a = 0; a < net.num_anchors(); ++a)
    blocks[static_cast<std::size_t>(net.anchor_node[a])].diagonal().array() -=
        cx * net.anchor_stiffness[a] + cv * net.anchor_damping[a];
  for (int i = 0; i < net.num_nodes(); ++i)
    blocks[static_cast<std::size_t>(i)].diagonal().array() -= cv * net.node_damping[i];
}

}  // namespace msfem::massspring
