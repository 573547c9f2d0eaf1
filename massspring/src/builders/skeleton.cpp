// Skeleton model (the pancreas seed): surface springs, a shrunken control mesh, and links from each
// surface vertex to its nearest control points.

#include <cmath>

#include "builder_support.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/surface_geometry.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {

SpringNetwork build_skeleton(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles,
                             const Eigen::MatrixX3d& control_vertices,
                             const Eigen::MatrixX3i& control_triangles,
                             const SkeletonOptions& options) {
  check_surface(vertices, triangles, "skeleton surface");
  detail::check_material(options.material);
  if (!std::isfinite(options.control_scale) || !(options.control_scale > 0.0) ||
      options.control_scale > 1.0)
    throw ModelError("skeleton control_scale " + std::to_string(options.control_scale) +
                     " must be in (0, 1]");
  if (options.links_per_vertex < 1)
    throw ModelError("skeleton links_per_vertex " + std::to_string(options.links_per_vertex) +
                     " must be >= 1");
  if (control_vertices.rows() < options.links_per_vertex)
    throw ModelError("skeleton control mesh: " + std::to_string(control_vertices.rows()) +
                     " control points, too few for " + std::to_string(options.links_per_vertex) +
                     " links per surface vertex");
  check_surface(control_vertices, control_triangles, "skeleton control mesh");

  const int nv = static_cast<int>(vertices.rows());
  const int nc = static_cast<int>(control_vertices.rows());
  const Eigen::Vector3d centroid = options.center.value_or(vertex_centroid(vertices));
  const Eigen::MatrixX3d control =
      ((control_vertices.rowwise() - centroid.transpose()) * options.control_scale).rowwise() +
      centroid.transpose();

  SpringNetwork network;
  detail::add_nodes(network, vertices, "surface");
  detail::add_nodes(network, control, "skeleton");

  const std::vector<std::string> names = spring_groups(options);  // surface, skeleton, links
  const int surface_group = add_springs(network, unique_edges(triangles), names[0]);
  std::vector<std::array<int, 2>> skeleton_edges;
  for (const auto& [a, b] : unique_edges(control_triangles))
    skeleton_edges.push_back({nv + a, nv + b});
  const int skeleton_group = add_springs(network, skeleton_edges, names[1]);
  std::vector<std::array<int, 2>> links;
  const auto nearest = nearest_points(control, vertices, options.links_per_vertex);
  for (int i = 0; i < nv; ++i)
    for (int c : nearest[i])
      links.push_back({i, nv + c});
  const int link_group = add_springs(network, links, names[2]);

  // Mass: half of ρV on the surface, half on the skeleton, each spread by vertex area.
  const double volume = std::abs(enclosed_volume(vertices, triangles));
  const double rho = options.material.density;
  const Eigen::VectorXd surface_areas = vertex_areas(vertices, triangles);
  const Eigen::VectorXd control_areas = vertex_areas(control, control_triangles);
  network.masses.head(nv) = 0.5 * rho * volume * surface_areas / surface_areas.sum();
  network.masses.tail(nc) = 0.5 * rho * volume * control_areas / control_areas.sum();
  Eigen::VectorXd weight(nv + nc);
  weight << surface_areas / surface_areas.mean(), control_areas / control_areas.mean();
  detail::assign_network_stiffness(network, {surface_group, skeleton_group, link_group},
                                   options.material.youngs_modulus, volume, weight);
  detail::assign_damping(network, options.material);

  for (int i = 0; i < nv; ++i)
    network.surface_nodes.push_back(i);
  if (options.fix_control_points)
    for (int c = 0; c < nc; ++c)
      network.fixed_nodes.push_back(nv + c);
  network.surface_triangles = triangles;
  network.validate();
  return network;
}

std::vector<std::string> spring_groups(const SkeletonOptions&) {
  return {"surface_edges", "skeleton_edges", "links"};
}

}  // namespace msfem::massspring
