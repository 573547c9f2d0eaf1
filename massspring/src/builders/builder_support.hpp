#pragma once

// Shared steps of the topology builders (internal to massspring).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "msfem/massspring/spring_network.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring::detail {

/// Throws ModelError naming the bad material parameter.
void check_material(const Material& material);

/// Appends nodes at `positions` in a new node group; masses are set to 1 until lumped.
void add_nodes(SpringNetwork& network, const Eigen::MatrixX3d& positions,
               const std::string& group_name);

/// Sets the stiffness of the springs of `groups` by the isotropic network rule over `volume`, each
/// spring's share of it in proportion to min(w_a, w_b) over its two nodes. `node_weight` is a
/// node's local measure of the region (its vertex area over the mean), so a refined patch is as
/// stiff per volume as the coarse surface around it; on a uniform surface every share is equal
/// (the seed's rule).
void assign_network_stiffness(SpringNetwork& network, const std::vector<int>& groups,
                              double youngs_modulus, double volume,
                              const Eigen::VectorXd& node_weight);

/// Applies the material's damping to every spring and node.
void assign_damping(SpringNetwork& network, const Material& material);

}  // namespace msfem::massspring::detail
