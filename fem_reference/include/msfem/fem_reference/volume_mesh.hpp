#pragma once

#include <Eigen/Core>
#include <vector>

namespace msfem::fem_reference {

/// Tetrahedra as four zero-based vertex ids per row, positively oriented
/// ((v1 - v0) x (v2 - v0) . (v3 - v0) > 0, deal.II's and Gmsh's reference ordering).
using TetrahedronArray = Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor>;

/// A tetrahedral volume mesh in plain arrays (metres), the hand-over between the Gmsh mesher and
/// the deal.II problem. When it was built from a closed surface, its first `num_surface_vertices`
/// vertices ARE the surface's vertices, in the surface's order and bit-identical: surface vertex i
/// is mesh vertex i, which makes the comparison with the mass-spring surface node to node.
struct VolumeMesh {
  Eigen::MatrixX3d vertices;
  TetrahedronArray tetrahedra;
  Eigen::Index num_surface_vertices = 0;

  Eigen::Index num_vertices() const { return vertices.rows(); }
  Eigen::Index num_tetrahedra() const { return tetrahedra.rows(); }
};

/// The four faces of a tetrahedron as local vertex triples (each face omits one vertex).
inline constexpr int tetrahedron_faces[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};

/// Sum of the tetrahedra's volumes.
double volume(const VolumeMesh& mesh);

/// Mass lumped to the vertices: each tetrahedron gives density * volume / 4 to each of its
/// vertices (kg), so a mass-spring model built on the same vertices weighs what the FEM body
/// weighs.
Eigen::VectorXd lumped_vertex_masses(const VolumeMesh& mesh, double density);

/// Shape quality of each tetrahedron: 2 sqrt(6) * inradius / longest edge, 1 for the regular
/// tetrahedron and 0 for a flat one (a sliver). Scale-free. Iterative solvers feel the worst cells:
/// the P2 brain needed twice the CG iterations with a worst cell of 0.001 than with one of 0.004.
Eigen::VectorXd cell_quality(const VolumeMesh& mesh);

/// Each tetrahedron split into eight (Bey's red refinement: four corner children and the inner
/// octahedron cut along its shortest diagonal, so the children's shape stays within a fixed factor
/// of the parent's), every edge's midpoint shared by the cells around it. The vertices keep their
/// ids (surface vertex i is still vertex i, and num_surface_vertices is unchanged); the midpoints
/// follow. The domain is the same polyhedron: a solve on it is the same problem at half the mesh
/// size, which is what the FEM reference's own error estimate compares against.
VolumeMesh refine_uniformly(const VolumeMesh& mesh);

/// Throws std::invalid_argument (one line naming the item) unless every tetrahedron refers to
/// existing vertices and has positive volume.
void check_volume_mesh(const VolumeMesh& mesh);

/// The part (0 .. parts - 1) of each tetrahedron: recursive coordinate bisection of the centroids,
/// each cut at the weighted median along the longest side of the part's box, so part sizes differ
/// by at most one cell per cut and interfaces are planar. Deterministic. The FEM's MPI partition:
/// METIS's cell graph costs 7 s of a 2-rank, 1.9 M-cell set-up, and this partition gives the same
/// CG iterations on the compact organs and shapes meshed here.
std::vector<unsigned int> partition_cells(const VolumeMesh& mesh, unsigned int parts);

}  // namespace msfem::fem_reference
