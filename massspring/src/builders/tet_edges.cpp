// Volumetric baseline: a spring on every edge of a tetrahedral mesh.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>

#include "builder_support.hpp"
#include "msfem/massspring/analytic_stiffness.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {
namespace {

constexpr int kTetEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
// Faces opposite corner 3, 2, 1, 0, ordered so that the normal points away from that corner for a
// positively oriented tetrahedron.
constexpr int kTetFaces[4][4] = {{0, 2, 1, 3}, {0, 1, 3, 2}, {0, 3, 2, 1}, {1, 2, 3, 0}};

double signed_tet_volume(const Eigen::MatrixX3d& v, const Eigen::Vector4i& t) {
  const Eigen::Vector3d a = v.row(t[0]);
  return (Eigen::Vector3d(v.row(t[1])) - a)
             .dot((Eigen::Vector3d(v.row(t[2])) - a).cross(Eigen::Vector3d(v.row(t[3])) - a)) /
         6.0;
}

}  // namespace

SpringNetwork build_tet_edges(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX4i& tetrahedra,
                              const TetEdgesOptions& options) {
  detail::check_material(options.material);
  const int nv = static_cast<int>(vertices.rows());
  if (nv < 4 || tetrahedra.rows() < 1)
    throw ModelError("tet_edges: " + std::to_string(nv) + " vertices and " +
                     std::to_string(tetrahedra.rows()) + " tetrahedra do not form a mesh");
  for (int i = 0; i < nv; ++i)
    if (!vertices.row(i).allFinite())
      throw ModelError("tet_edges vertex " + std::to_string(i) + ": coordinate not finite");

  const double modulus = options.material.youngs_modulus;
  SpringNetwork network;
  detail::add_nodes(network, vertices, "volume");
  Eigen::VectorXd masses = Eigen::VectorXd::Zero(nv);
  std::map<std::array<int, 2>, double> edge_stiffness;  // sorted, so spring order is reproducible
  std::map<std::array<int, 3>, std::array<int, 4>> faces;  // sorted corners -> oriented face, count
  for (Eigen::Index t = 0; t < tetrahedra.rows(); ++t) {
    const Eigen::Vector4i tet = tetrahedra.row(t).transpose();
    for (int c = 0; c < 4; ++c)
      if (tet[c] < 0 || tet[c] >= nv)
        throw ModelError("tetrahedron " + std::to_string(t) + ": vertex id " +
                         std::to_string(tet[c]) + " out of range [0, " + std::to_string(nv) + ")");
    const double signed_volume = signed_tet_volume(vertices, tet);
    const double volume = std::abs(signed_volume);
    if (!(volume > 0.0))
      throw ModelError("tetrahedron " + std::to_string(t) + ": zero volume (degenerate)");
    for (int c = 0; c < 4; ++c)
      masses[tet[c]] += options.material.density * volume / 4.0;
    for (const auto& e : kTetEdges) {
      const int a = std::min(tet[e[0]], tet[e[1]]);
      const int b = std::max(tet[e[0]], tet[e[1]]);
      const double length = (vertices.row(b) - vertices.row(a)).norm();
      edge_stiffness[{a, b}] += options.stiffness_rule == TetStiffnessRule::lloyd
                                    ? lloyd_tet_edge_stiffness(modulus, length)
                                    : van_gelder_stiffness(modulus, volume, length);
    }
    for (const auto& f : kTetFaces) {
      std::array<int, 3> face = {tet[f[0]], tet[f[1]], tet[f[2]]};
      if (signed_volume < 0.0) std::swap(face[1], face[2]);
      std::array<int, 3> key = face;
      std::sort(key.begin(), key.end());
      auto [it, inserted] =
          faces.try_emplace(key, std::array<int, 4>{face[0], face[1], face[2], 0});
      ++it->second[3];
    }
  }

  std::vector<std::array<int, 2>> pairs;
  for (const auto& entry : edge_stiffness)
    pairs.push_back(entry.first);
  add_springs(network, pairs, spring_groups(options)[0]);
  int s = 0;
  for (const auto& entry : edge_stiffness)
    network.stiffness[s++] = entry.second;
  for (int i = 0; i < nv; ++i)
    if (!(masses[i] > 0.0))
      throw ModelError("tet_edges vertex " + std::to_string(i) + ": belongs to no tetrahedron");
  network.masses = masses;
  detail::assign_damping(network, options.material);

  // Boundary = faces used by exactly one tetrahedron.
  std::vector<Eigen::RowVector3i> boundary;
  std::vector<char> on_surface(nv, 0);
  for (const auto& entry : faces)
    if (entry.second[3] == 1) {
      boundary.emplace_back(entry.second[0], entry.second[1], entry.second[2]);
      for (int c = 0; c < 3; ++c)
        on_surface[entry.second[c]] = 1;
    }
  network.surface_triangles.resize(static_cast<Eigen::Index>(boundary.size()), 3);
  for (std::size_t f = 0; f < boundary.size(); ++f)
    network.surface_triangles.row(f) = boundary[f];
  for (int i = 0; i < nv; ++i)
    if (on_surface[i]) network.surface_nodes.push_back(i);
  network.validate();
  return network;
}

std::vector<std::string> spring_groups(const TetEdgesOptions&) {
  return {"tet_edges"};
}

}  // namespace msfem::massspring
