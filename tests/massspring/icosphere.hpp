#pragma once

// Test meshes made here, so that the massspring tests need nothing outside massspring.

#include <Eigen/Core>

namespace msfem::massspring::testing {

struct TriangleMesh {
  Eigen::MatrixX3d vertices;
  Eigen::MatrixX3i triangles;
};

/// Icosahedron subdivided `level` times, vertices on the sphere: 10·4ⁿ+2 vertices, 30·4ⁿ edges,
/// 20·4ⁿ triangles, counter-clockwise seen from outside.
TriangleMesh icosphere(int level, double radius,
                       const Eigen::Vector3d& center = Eigen::Vector3d::Zero());

/// A closed concave surface that is not star-shaped about its centroid: an ellipsoid (semi-axes
/// 3, 0.6, 0.6 × size) bent along a circle of radius 1.2 × size through ±143°, a banana whose
/// centroid lies in the hole; scaling it about the centroid moves inner-tier points outside.
TriangleMesh bent_banana(int level, double size);

/// Unit cube [0, 1]³ split into six tetrahedra around the main diagonal (Kuhn): 8 vertices,
/// 19 edges, 12 boundary triangles.
void kuhn_cube(Eigen::MatrixX3d& vertices, Eigen::MatrixX4i& tetrahedra);

}  // namespace msfem::massspring::testing
