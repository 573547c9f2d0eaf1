#pragma once

#include <Eigen/Core>
#include <vector>

#include "msfem/fem_reference/volume_mesh.hpp"

namespace msfem::fem_reference {

/// Smaller cells inside a ball (the tool's neighbourhood): `cell_size` within `radius` of `center`,
/// growing linearly to the global size over `transition` beyond it.
struct LocalRefinement {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0.0;
  double transition = 0.0;
  double cell_size = 0.0;
};

struct MeshOptions {
  /// Target edge length of the interior tetrahedra in metres; 0 means the mean edge length of the
  /// surface. Boundary triangles are never changed: their size is the surface's.
  double cell_size = 0.0;
  /// Balls of smaller cells (the size field is the smallest any of them asks for).
  std::vector<LocalRefinement> refinements;
  /// Gmsh's Mesh.Algorithm3D: 1 = Delaunay (default: the same mesh on every run), 10 = HXT
  /// (several times faster on large meshes, but Gmsh 4.8's HXT differs from run to run).
  int algorithm_3d = 1;
  /// When the worst tetrahedron's quality (cell_quality) after Gmsh's own optimisation is below
  /// this, Gmsh's "Relocate3D" pass moves interior vertices to raise it; 0 never. Large surface
  /// triangles over a finer interior (the brain's) leave flat cells the default pass keeps: on the
  /// 1.2 M-DoF brain at P2 the worst rose from 0.001 to 0.004 and CG needed 101 instead of 198
  /// iterations (results/BENCHMARKS.md). Well-shaped meshes (a sphere's worst is 0.3) skip the
  /// pass, which costs 8 s at 1.9 M cells.
  double relocate_below_quality = 0.02;
};

/// Throws std::invalid_argument naming the first defect unless the triangles form a closed,
/// consistently oriented 2-manifold over existing vertices: every directed edge (a, b) appears once
/// and its reverse (b, a) once.
void check_closed_surface(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles);

/// Tetrahedralises the volume bounded by a closed surface (metres, zero-based, counter-clockwise
/// seen from outside) with Gmsh, keeping the surface triangulation as the mesh boundary: mesh
/// vertex i == surface vertex i for i < vertices.rows() (no Steiner points on the boundary; a
/// FemError is thrown if Gmsh had to add any). Throws std::invalid_argument for a non-closed
/// surface.
VolumeMesh mesh_closed_surface(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& triangles,
                               const MeshOptions& options = {});

}  // namespace msfem::fem_reference
