#pragma once
// Small hand-made surfaces whose every property is known, for the cases/ tests.

#include <cmath>

#include "msfem/cases/surface.hpp"

namespace msfem::cases::testing {

/// Regular octahedron of "radius" r: 6 vertices, 12 edges, 8 outward triangles, volume 4r³/3.
inline Surface octahedron(double r = 1.0, const Eigen::Vector3d& shift = Eigen::Vector3d::Zero()) {
  Surface s;
  s.vertices.resize(6, 3);
  s.vertices << r, 0, 0, -r, 0, 0, 0, r, 0, 0, -r, 0, 0, 0, r, 0, 0, -r;
  s.vertices.rowwise() += shift.transpose();
  s.triangles.resize(8, 3);
  s.triangles << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  return s;
}

/// Tetrahedron with outward triangles on vertices offset..offset+3 (for gluing meshes together).
inline Surface tetrahedron(const Eigen::Vector3d& shift = Eigen::Vector3d::Zero()) {
  Surface s;
  s.vertices.resize(4, 3);
  s.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  s.vertices.rowwise() += shift.transpose();
  s.triangles.resize(4, 3);
  s.triangles << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  return s;
}

/// Torus with n x m quads split into triangles: genus 1, V = n m, E = 3 n m, F = 2 n m.
inline Surface torus(int n, int m, double major = 1.0, double minor = 0.3) {
  Surface s;
  s.vertices.resize(n * m, 3);
  s.triangles.resize(2 * n * m, 3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double u = 2 * M_PI * i / n, v = 2 * M_PI * j / m;
      s.vertices.row(i * m + j) << (major + minor * std::cos(v)) * std::cos(u),
          (major + minor * std::cos(v)) * std::sin(u), minor * std::sin(v);
      const int a = i * m + j, b = ((i + 1) % n) * m + j, c = ((i + 1) % n) * m + (j + 1) % m,
                d = i * m + (j + 1) % m;
      s.triangles.row(2 * (i * m + j)) << a, b, c;
      s.triangles.row(2 * (i * m + j) + 1) << a, c, d;
    }
  return s;
}

/// Both surfaces in one, the second's vertex ids shifted past the first's.
inline Surface merged(const Surface& a, const Surface& b) {
  Surface s;
  s.vertices.resize(a.num_vertices() + b.num_vertices(), 3);
  s.vertices << a.vertices, b.vertices;
  s.triangles.resize(a.num_triangles() + b.num_triangles(), 3);
  s.triangles << a.triangles, (b.triangles.array() + static_cast<int>(a.num_vertices())).matrix();
  return s;
}

}  // namespace msfem::cases::testing
