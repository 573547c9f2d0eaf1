#include "msfem/fem_reference/surface_mesher.hpp"

#include <gmsh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "gmsh_session.hpp"
#include "msfem/fem_reference/errors.hpp"

namespace msfem::fem_reference {

namespace {

constexpr int gmsh_triangle = 2;

std::string edge_name(int a, int b) {
  return "(" + std::to_string(a) + ", " + std::to_string(b) + ")";
}

double mean_edge_length(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles) {
  double sum = 0.0;
  for (Eigen::Index t = 0; t < triangles.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      sum += (vertices.row(triangles(t, k)) - vertices.row(triangles(t, (k + 1) % 3))).norm();
  return sum / double(3 * triangles.rows());
}

/// The size field: the global size, smaller in each refinement ball with a linear transition.
double target_size(const MeshOptions& options, double global_size, const Eigen::Vector3d& x) {
  double size = global_size;
  for (const LocalRefinement& r : options.refinements) {
    const double outside = std::max(0.0, (x - r.center).norm() - r.radius);
    if (r.transition <= 0.0) {
      if (outside <= 0.0) size = std::min(size, r.cell_size);
      continue;
    }
    const double w = std::min(1.0, outside / r.transition);
    size = std::min(size, (1.0 - w) * r.cell_size + w * global_size);
  }
  return size;
}

}  // namespace

void check_closed_surface(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles) {
  if (vertices.rows() < 4 || triangles.rows() < 4)
    throw std::invalid_argument("surface is not closed: it has " + std::to_string(vertices.rows()) +
                                " vertices and " + std::to_string(triangles.rows()) +
                                " triangles (a closed surface needs at least 4 of each)");
  if (!vertices.allFinite()) throw std::invalid_argument("surface has a non-finite coordinate");
  // Each directed edge of a closed, consistently oriented surface occurs exactly once and its
  // reverse once (in the neighbouring triangle).
  std::map<std::pair<int, int>, int> directed_edges;
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = triangles(t, k), b = triangles(t, (k + 1) % 3);
      if (a < 0 || a >= vertices.rows())
        throw std::invalid_argument("surface triangle " + std::to_string(t) +
                                    " refers to missing vertex " + std::to_string(a));
      if (a == b)
        throw std::invalid_argument("surface triangle " + std::to_string(t) + " is degenerate");
      if (++directed_edges[{a, b}] > 1)
        throw std::invalid_argument("surface is not a consistently oriented manifold: edge " +
                                    edge_name(a, b) + " is used twice in the same direction");
    }
  }
  for (const auto& [edge, count] : directed_edges)
    if (directed_edges.count({edge.second, edge.first}) == 0)
      throw std::invalid_argument("surface is not closed: edge " +
                                  edge_name(edge.first, edge.second) +
                                  " borders only one triangle");
}

VolumeMesh mesh_closed_surface(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles,
                               const MeshOptions& options) {
  check_closed_surface(vertices, triangles);
  const double global_size =
      options.cell_size > 0.0 ? options.cell_size : mean_edge_length(vertices, triangles);

  detail::GmshSession session;
  // The surface becomes a discrete entity with node tags 1..n, so the volume mesher sees it as a
  // fixed boundary mesh; no classifySurfaces/createGeometry, which would allow remeshing it.
  const int surface_tag = gmsh::model::addDiscreteEntity(2);
  std::vector<std::size_t> node_tags(std::size_t(vertices.rows()));
  std::vector<double> coordinates(3 * node_tags.size());
  for (std::size_t i = 0; i < node_tags.size(); ++i) {
    node_tags[i] = i + 1;
    for (int d = 0; d < 3; ++d)
      coordinates[3 * i + d] = vertices(Eigen::Index(i), d);
  }
  gmsh::model::mesh::addNodes(2, surface_tag, node_tags, coordinates);
  std::vector<std::size_t> triangle_nodes(3 * std::size_t(triangles.rows()));
  for (Eigen::Index t = 0; t < triangles.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      triangle_nodes[3 * std::size_t(t) + k] = std::size_t(triangles(t, k)) + 1;
  gmsh::model::mesh::addElementsByType(surface_tag, gmsh_triangle, {}, triangle_nodes);
  // A built-in-kernel volume bounded by the discrete surface: its boundary mesh is taken as is.
  const int shell = gmsh::model::geo::addSurfaceLoop({surface_tag});
  gmsh::model::geo::addVolume({shell});
  gmsh::model::geo::synchronize();

  gmsh::option::setNumber("Mesh.Algorithm3D", options.algorithm_3d);
  // HXT is not reproducible even on one thread; when it is asked for, let it use every core.
  if (options.algorithm_3d == 10) gmsh::option::setNumber("General.NumThreads", 0);
  gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
  gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  gmsh::option::setNumber("Mesh.MeshSizeMax", global_size);
  gmsh::option::setNumber("Mesh.Optimize", 1);
  gmsh::model::mesh::setSizeCallback(
      [&options, global_size](int, int, double x, double y, double z) {
        return target_size(options, global_size, Eigen::Vector3d(x, y, z));
      });

  VolumeMesh mesh = detail::generate_tetrahedra(node_tags.size(), options.relocate_below_quality);
  // Node-to-node comparison with the mass-spring surface needs the surface vertices untouched.
  if (mesh.vertices.topRows(vertices.rows()) != vertices)
    throw FemError("Gmsh moved a surface vertex while meshing the volume");
  // Boundary recovery may add Steiner points on the surface; then vertex i would no longer be the
  // only boundary node near surface vertex i. Compare the boundary faces with the input triangles.
  // Every face sorted, then counted by runs (a map of 7 M faces took seconds at 1 M DoFs).
  std::vector<std::array<int, 3>> faces;
  faces.reserve(4 * std::size_t(mesh.num_tetrahedra()));
  for (Eigen::Index e = 0; e < mesh.num_tetrahedra(); ++e) {
    for (const auto& f : tetrahedron_faces) {
      std::array<int, 3> key{
          {mesh.tetrahedra(e, f[0]), mesh.tetrahedra(e, f[1]), mesh.tetrahedra(e, f[2])}};
      std::sort(key.begin(), key.end());
      faces.push_back(key);
    }
  }
  std::sort(faces.begin(), faces.end());
  Eigen::Index boundary_faces = 0;
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j] == faces[i])
      ++j;
    if (j - i == 1) {
      ++boundary_faces;
      if (faces[i][2] >= vertices.rows())
        throw FemError("Gmsh inserted a Steiner point on the surface (mesh vertex " +
                       std::to_string(faces[i][2]) + "); the surface may self-intersect");
    }
    i = j;
  }
  if (boundary_faces != triangles.rows())
    throw FemError("volume mesh has " + std::to_string(boundary_faces) +
                   " boundary faces, surface has " + std::to_string(triangles.rows()) +
                   " triangles");
  return mesh;
}

}  // namespace msfem::fem_reference
