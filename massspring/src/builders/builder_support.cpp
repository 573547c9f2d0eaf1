#include "builder_support.hpp"

#include <algorithm>
#include <cmath>

#include "msfem/massspring/analytic_stiffness.hpp"
#include "msfem/massspring/errors.hpp"

namespace msfem::massspring::detail {

void check_material(const Material& material) {
  auto check = [](double value, const char* name, bool strictly_positive) {
    if (!std::isfinite(value) || value < 0.0 || (strictly_positive && value == 0.0))
      throw ModelError(
          std::string("material ") + name + " " + std::to_string(value) +
          (strictly_positive ? " must be finite and > 0" : " must be finite and >= 0"));
  };
  check(material.youngs_modulus, "youngs_modulus", true);
  check(material.density, "density", true);
  check(material.spring_damping, "spring_damping", false);
  check(material.node_damping, "node_damping", false);
}

void add_nodes(SpringNetwork& network, const Eigen::MatrixX3d& positions,
               const std::string& group_name) {
  const int group = static_cast<int>(network.node_group_names.size());
  network.node_group_names.push_back(group_name);
  const Eigen::Index old = network.rest_positions.rows();
  const Eigen::Index total = old + positions.rows();
  network.rest_positions.conservativeResize(total, 3);
  network.rest_positions.bottomRows(positions.rows()) = positions;
  network.masses.conservativeResize(total);
  network.masses.tail(positions.rows()).setOnes();
  network.node_damping.conservativeResize(total);
  network.node_damping.tail(positions.rows()).setZero();
  network.node_group.conservativeResize(total);
  network.node_group.tail(positions.rows()).setConstant(group);
}

void assign_network_stiffness(SpringNetwork& network, const std::vector<int>& groups,
                              double youngs_modulus, double volume,
                              const Eigen::VectorXd& node_weight) {
  std::vector<int> members;
  for (int s = 0; s < network.num_springs(); ++s)
    if (std::find(groups.begin(), groups.end(), network.spring_group[s]) != groups.end())
      members.push_back(s);
  Eigen::VectorXd lengths(members.size()), shares(members.size());
  for (std::size_t k = 0; k < members.size(); ++k) {
    lengths[k] = network.rest_length[members[k]];
    // The finer end sets the share: a fine surface node's link to a coarse control point stands
    // for the fine node's patch, not the control point's.
    shares[k] = std::min(node_weight[network.springs(members[k], 0)],
                         node_weight[network.springs(members[k], 1)]);
  }
  const Eigen::VectorXd k = isotropic_network_stiffness(youngs_modulus, volume, lengths, shares);
  for (std::size_t m = 0; m < members.size(); ++m)
    network.stiffness[members[m]] = k[m];
}

void assign_damping(SpringNetwork& network, const Material& material) {
  network.damping.setConstant(network.num_springs(), material.spring_damping);
  network.node_damping.setConstant(network.num_nodes(), material.node_damping);
  network.anchor_damping.setConstant(network.num_anchors(), material.spring_damping);
}

}  // namespace msfem::massspring::detail
