// Single-layer surface model: springs on the surface edges only, optionally anchored to rest.

#include <cmath>

#include "builder_support.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/surface_geometry.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {

SpringNetwork build_single_layer(const Eigen::MatrixX3d& vertices,
                                 const Eigen::MatrixX3i& triangles,
                                 const SingleLayerOptions& options) {
  check_surface(vertices, triangles, "single_layer surface");
  detail::check_material(options.material);
  if (!std::isfinite(options.anchor_ratio) || options.anchor_ratio < 0.0)
    throw ModelError("single_layer anchor_ratio " + std::to_string(options.anchor_ratio) +
                     " must be finite and >= 0");

  const int nv = static_cast<int>(vertices.rows());
  SpringNetwork network;
  detail::add_nodes(network, vertices, "surface");
  const int edges = add_springs(network, unique_edges(triangles), spring_groups(options)[0]);

  // A shell has no volume of its own: the enclosed volume sets the mass and, through the isotropic
  // network rule, the order of magnitude of the edge stiffness.
  const double volume = std::abs(enclosed_volume(vertices, triangles));
  const Eigen::VectorXd areas = vertex_areas(vertices, triangles);
  network.masses = options.material.density * volume * areas / areas.sum();
  detail::assign_network_stiffness(network, {edges}, options.material.youngs_modulus, volume,
                                   areas / areas.mean());

  if (options.anchor_to_rest) {
    Eigen::VectorXd summed = Eigen::VectorXd::Zero(nv);
    for (int s = 0; s < network.num_springs(); ++s) {
      summed[network.springs(s, 0)] += network.stiffness[s];
      summed[network.springs(s, 1)] += network.stiffness[s];
    }
    network.anchor_node = Eigen::VectorXi::LinSpaced(nv, 0, nv - 1);
    network.anchor_point = vertices;
    // Weighted by the node's share of the area: the anchors stand for an elastic foundation, whose
    // stiffness per unit area must not grow where the surface is finer (a refined patch at the
    // tool, a simplified organ's small triangles), while the edges' summed stiffness stays about
    // the same at any edge length (the network rule's k does not depend on it).
    network.anchor_stiffness = options.anchor_ratio * summed.cwiseProduct(areas / areas.mean());
    network.anchor_damping = Eigen::VectorXd::Zero(nv);
  } else {
    network.anchor_node.resize(0);
    network.anchor_point.resize(0, 3);
    network.anchor_stiffness.resize(0);
    network.anchor_damping.resize(0);
  }
  detail::assign_damping(network, options.material);

  for (int i = 0; i < nv; ++i)
    network.surface_nodes.push_back(i);
  network.surface_triangles = triangles;
  network.validate();
  return network;
}

std::vector<std::string> spring_groups(const SingleLayerOptions&) {
  return {"surface_edges"};
}

}  // namespace msfem::massspring
