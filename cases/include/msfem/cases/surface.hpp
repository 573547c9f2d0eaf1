#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <vector>

namespace msfem::cases {

/// A triangulated closed surface: vertices (n x 3, metres) and triangles (m x 3, zero-based vertex
/// ids, counter-clockwise seen from outside). The arrays are plain Eigen matrices so that
/// massspring, which must not depend on this library, takes the same data without conversion.
struct Surface {
  Eigen::MatrixX3d vertices;
  Eigen::MatrixX3i triangles;

  Eigen::Index num_vertices() const { return vertices.rows(); }
  Eigen::Index num_triangles() const { return triangles.rows(); }
};

/// An undirected edge with the smaller vertex id first.
using Edge = std::array<int, 2>;

/// Unique undirected edges, sorted.
std::vector<Edge> unique_edges(const Surface& surface);

/// Signed enclosed volume (divergence theorem); positive for an outward-oriented closed surface.
double signed_volume(const Surface& surface);

/// Total area of the triangles.
double area(const Surface& surface);

/// Mean of the vertex positions (the "centroid" the scaled inner tiers of the layered model use).
Eigen::Vector3d vertex_centroid(const Surface& surface);

/// Axis-aligned bounding box: row 0 = minimum corner, row 1 = maximum corner.
Eigen::Matrix<double, 2, 3> bounding_box(const Surface& surface);

/// Per-vertex unit normals, area-weighted from the incident triangles.
Eigen::MatrixX3d vertex_normals(const Surface& surface);

/// Multiplies every coordinate by factor (unit conversion).
void scale(Surface& surface, double factor);

}  // namespace msfem::cases
