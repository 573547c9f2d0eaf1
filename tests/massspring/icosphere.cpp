#include "icosphere.hpp"

#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace msfem::massspring::testing {

TriangleMesh icosphere(int level, double radius, const Eigen::Vector3d& center) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> points = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                         {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                         {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : points)
    p.normalize();
  std::vector<Eigen::Vector3i> faces = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> midpoint;
    auto middle = [&](int a, int b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      const auto found = midpoint.find(key);
      if (found != midpoint.end()) return found->second;
      points.push_back((points[a] + points[b]).normalized());
      const int id = static_cast<int>(points.size()) - 1;
      midpoint.emplace(key, id);
      return id;
    };
    std::vector<Eigen::Vector3i> finer;
    for (const auto& f : faces) {
      const int ab = middle(f[0], f[1]), bc = middle(f[1], f[2]), ca = middle(f[2], f[0]);
      finer.push_back({f[0], ab, ca});
      finer.push_back({f[1], bc, ab});
      finer.push_back({f[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    faces.swap(finer);
  }
  TriangleMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i)
    mesh.vertices.row(i) = (center + radius * points[i]).transpose();
  mesh.triangles.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f)
    mesh.triangles.row(f) = faces[f].transpose();
  return mesh;
}

TriangleMesh bent_banana(int level, double size) {
  TriangleMesh mesh = icosphere(level, 1.0);
  const double bend_radius = 1.2;
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    const double x = 3.0 * mesh.vertices(i, 0);
    const double y = 0.6 * mesh.vertices(i, 1);
    const double z = 0.6 * mesh.vertices(i, 2);
    const double angle = x / bend_radius;
    const double r = bend_radius + y;  // keeps the orientation (positive Jacobian)
    mesh.vertices.row(i) << size * r * std::sin(angle), size * r * std::cos(angle), size * z;
  }
  return mesh;
}

void kuhn_cube(Eigen::MatrixX3d& vertices, Eigen::MatrixX4i& tetrahedra) {
  vertices.resize(8, 3);
  for (int i = 0; i < 8; ++i)
    vertices.row(i) << (i & 1), (i >> 1) & 1, (i >> 2) & 1;
  // Paths from corner 0 to corner 7 through the cube's edges, one tetrahedron each.
  tetrahedra.resize(6, 4);
  tetrahedra << 0, 1, 3, 7, 0, 1, 5, 7, 0, 2, 3, 7, 0, 2, 6, 7, 0, 4, 5, 7, 0, 4, 6, 7;
}

}  // namespace msfem::massspring::testing
