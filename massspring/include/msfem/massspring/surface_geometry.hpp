#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

namespace msfem::massspring {

/// Geometry of a closed triangulated surface given as arrays (vertices in metres, triangles
/// zero-based and counter-clockwise seen from outside). massspring keeps its own small versions of
/// these so that it depends on Eigen only.

/// Throws ModelError naming the first bad item: empty arrays, a non-finite vertex, an index out of
/// range, a triangle with a repeated vertex. `what` prefixes the message ("surface", "control
/// mesh").
void check_surface(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles,
                   const char* what);

/// Unique undirected edges (smaller id first), sorted.
std::vector<std::array<int, 2>> unique_edges(const Eigen::MatrixX3i& triangles);

/// Signed enclosed volume (divergence theorem); positive for an outward-oriented closed surface.
double enclosed_volume(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles);

/// Mean of the vertices.
Eigen::Vector3d vertex_centroid(const Eigen::MatrixX3d& vertices);

/// Area-weighted unit vertex normals (outward for a CCW surface).
Eigen::MatrixX3d vertex_normals(const Eigen::MatrixX3d& vertices,
                                const Eigen::MatrixX3i& triangles);

/// One third of the incident triangle areas per vertex (sums to the surface area).
Eigen::VectorXd vertex_areas(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles);

/// Points that lie outside the closed surface, by the test "(p - v)·n_v > 0 for the nearest surface
/// vertex v" (k-d tree). Exact for convex surfaces and points well inside; a fast screen, not a
/// full winding number, near sharp concave folds. Returns their indices.
std::vector<int> points_outside_surface(const Eigen::MatrixX3d& points,
                                        const Eigen::MatrixX3d& vertices,
                                        const Eigen::MatrixX3i& triangles);

/// For each query point, the ids of its k nearest points among `points` (k-d tree, nanoflann),
/// nearest first.
std::vector<std::vector<int>> nearest_points(const Eigen::MatrixX3d& points,
                                             const Eigen::MatrixX3d& queries, int k);

}  // namespace msfem::massspring
