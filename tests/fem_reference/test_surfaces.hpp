#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace msfem::fem_reference::testing {

/// A closed triangulated surface for the tests (kept here so the tests do not depend on the cases
/// library): vertices (metres) and counter-clockwise outward triangles.
struct TestSurface {
  Eigen::MatrixX3d vertices;
  Eigen::MatrixX3i triangles;
};

/// Icosahedron subdivided `level` times and projected onto the sphere of `radius` about the origin
/// (10 * 4^level + 2 vertices).
inline TestSurface icosphere(int level, double radius) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<Eigen::Vector3i> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& p : v)
    p.normalize();
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return midpoint[key] = int(v.size()) - 1;
    };
    std::vector<Eigen::Vector3i> refined;
    for (const auto& tri : f) {
      const int ab = mid(tri[0], tri[1]), bc = mid(tri[1], tri[2]), ca = mid(tri[2], tri[0]);
      refined.push_back({tri[0], ab, ca});
      refined.push_back({tri[1], bc, ab});
      refined.push_back({tri[2], ca, bc});
      refined.push_back({ab, bc, ca});
    }
    f = std::move(refined);
  }
  TestSurface s;
  s.vertices.resize(Eigen::Index(v.size()), 3);
  s.triangles.resize(Eigen::Index(f.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i)
    s.vertices.row(Eigen::Index(i)) = radius * v[i].transpose();
  for (std::size_t i = 0; i < f.size(); ++i)
    s.triangles.row(Eigen::Index(i)) = f[i].transpose();
  return s;
}

}  // namespace msfem::fem_reference::testing
