#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "msfem/fem_reference/volume_mesh.hpp"

namespace msfem::fem_reference {

/// A set of points (a support's or a load's footprint), tested at DoF support points or face
/// centroids.
using Region = std::function<bool(const Eigen::Vector3d& x)>;
/// A vector field of position (displacement in m, body force in N/m^3).
using VectorField = std::function<Eigen::Vector3d(const Eigen::Vector3d& x)>;
using ScalarField = std::function<double(const Eigen::Vector3d& x)>;
/// Traction in Pa at a boundary point with the (faceted) outward unit normal there.
using TractionField =
    std::function<Eigen::Vector3d(const Eigen::Vector3d& x, const Eigen::Vector3d& outward_normal)>;

/// Isotropic linear elastic material in SI units.
struct Material {
  double youngs_modulus = 0.0;       ///< Pa; used unless youngs_modulus_field is set
  ScalarField youngs_modulus_field;  ///< optional E(x) in Pa, evaluated at quadrature points
  double poisson_ratio = 0.0;        ///< in (-1, 0.5)
  double density = 0.0;              ///< kg/m^3
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  ///< m/s^2; body force density * gravity
};

/// Prescribed displacement of every DoF node (vertices; for P2 also edge midpoints) that lies in
/// `region` (only boundary nodes when `boundary_nodes_only`), for the selected components. An empty
/// `displacement` clamps (u = 0). A node caught by several supports takes the first one listed.
struct Support {
  std::string name;
  Region region;
  VectorField displacement;
  std::array<bool, 3> components{{true, true, true}};
  bool boundary_nodes_only = false;
};

/// Surface load on the boundary faces whose centroid lies in `region`.
struct Traction {
  std::string name;
  Region region;
  TractionField traction;
};

/// A rigid sphere the body may touch without friction (Signorini conditions): a boundary node may
/// not enter it, and it can only push. Solved by a semi-smooth Newton (primal-dual active set)
/// iteration on a nodal penalty: a node is active when it lies inside the sphere; an active node
/// gets the normal spring k n n^T towards the sphere's surface along the sphere's normal at the
/// node's present position (tangential motion free), with k = penalty_factor times the node's
/// diagonal stiffness. The first iterate takes each node inside the sphere to where the sphere,
/// pushed along its axis, would have carried it. Each iteration is one linear solve started from
/// the last solution, with the first one's preconditioner, to a loose tolerance until the active
/// set repeats and then once to the solver's own. The penetration left is the node's contact force
/// over k: at the default factor about 2e-4 of the depth (msfem verify's Hertz checks), a force
/// error of the same order.
struct SphereObstacle {
  std::string name;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0.0;
  /// Direction the sphere is pushed into the body; the contact radius is measured about the axis
  /// through `center` along it.
  Eigen::Vector3d push_direction = -Eigen::Vector3d::UnitZ();
  /// Boundary nodes that may touch it; unset: every boundary node.
  Region candidates;
  double penalty_factor = 1e2;
  int max_iterations = 30;
};

/// The state of one SphereObstacle's contact after the solve.
struct ContactReport {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< N, the sphere's force on the body
  int active_nodes = 0;
  int iterations = 0;  ///< active-set iterations, one linear solve each
  /// m, sqrt(5/2 <r^2>_F): the contact forces' second moment about the axis. Exact for a Hertzian
  /// pressure p0 sqrt(1 - r^2/a^2), and from consistent nodal forces (P2) exact for any pressure's
  /// moment, so it does not jump by a cell when one more node touches.
  double contact_radius = 0.0;
  double outermost_node_radius = 0.0;  ///< m, the active node farthest from the axis
  double max_penetration = 0.0;        ///< m, the deepest node inside the sphere
};

enum class Preconditioner {
  gamg,        ///< PETSc CG + GAMG with the six rigid-body modes as near-null space (default)
  boomer_amg,  ///< PETSc CG + hypre BoomerAMG
  mumps        ///< direct: MUMPS LU
};

struct SolverSettings {
  Preconditioner preconditioner = Preconditioner::gamg;
  double relative_tolerance = 1e-10;  ///< on the preconditioned residual norm
  int max_iterations = 2000;
  /// P2 with GAMG: precondition with two levels, the P2 space over the P1 space of the same mesh
  /// (GAMG on that), instead of GAMG on the P2 matrix: about half the CG iterations on the brain.
  bool p_multigrid = true;
};

/// Everything the FEM needs besides the mesh.
struct ElasticityModel {
  unsigned int degree = 1;  ///< 1 or 2: FE_SimplexP<3>(degree)^3 with MappingFE(FE_SimplexP<3>(1))
  Material material;
  std::vector<Support> supports;
  std::vector<Traction> tractions;
  VectorField body_force;  ///< optional, N/m^3, added to density * gravity
  std::vector<SphereObstacle> obstacles;
  SolverSettings solver;
  /// Optional, m: a guess of the displacement at a point (a coarser mesh's solution). With
  /// obstacles, the contact iteration starts from it (its active set and normals) instead of from
  /// Hertz's radius; the answer is the same, reached in fewer iterations.
  VectorField initial_displacement;
};

struct SolveStatistics {
  std::size_t dofs = 0;
  std::size_t cells = 0;
  std::size_t vertices = 0;
  std::size_t prescribed_dofs = 0;
  int mpi_ranks = 1;
  int iterations = 0;  ///< Krylov iterations, summed over the contact's active-set iterations
  double residual_norm = 0.0;  ///< final (preconditioned) residual norm
  /// Smallest and largest E at the quadrature points the stiffness matrix was assembled at (both
  /// the constant E without a field).
  double youngs_modulus_min = 0.0, youngs_modulus_max = 0.0;
  double setup_time_s = 0.0;
  double assemble_time_s = 0.0;
  double solve_time_s = 0.0;
};

/// Static linear elasticity on a tetrahedral mesh with deal.II (simplex P1/P2) and PETSc, in the
/// order of deal.II's step-8: setup_system, assemble_system, solve, then queries. All ranks of
/// MPI_COMM_WORLD must construct and run it together (a parallel::shared::Triangulation
/// partitioned by coordinate bisection, partition_cells); the mesh of rank 0 is used (broadcast;
/// other ranks may pass an empty one), and every query returns the same complete answer on every
/// rank. MPI and PETSc are initialised on first use if the program has not done so (and finalised
/// at exit).
///
/// Throws std::invalid_argument for bad input (E <= 0, nu outside (-1, 0.5), a degree other than 1
/// or 2, a support or traction region that catches nothing), FemError when there is no support
/// (the stiffness matrix would be singular) and SolverError when the Krylov solver does not
/// converge.
class ElasticityProblem {
 public:
  ElasticityProblem(const VolumeMesh& mesh, ElasticityModel model);
  ~ElasticityProblem();
  ElasticityProblem(const ElasticityProblem&) = delete;
  ElasticityProblem& operator=(const ElasticityProblem&) = delete;

  /// setup_system + assemble_system + solve.
  void run();

  /// Displacement (m) at every mesh vertex, in the mesh's vertex order; its first
  /// mesh.num_surface_vertices rows are the surface vertices' displacements.
  Eigen::MatrixX3d vertex_displacements() const;

  /// Displacement at arbitrary points (R-tree point locator; points just outside the faceted
  /// domain are taken from the nearest cell).
  Eigen::MatrixX3d displacements_at(const Eigen::MatrixX3d& points) const;

  /// Force (N) that the named support exerts on the body: the residual K u - f summed over the
  /// support's prescribed DoFs, per component. The force the body exerts on a tool is its negative.
  Eigen::Vector3d reaction_force(const std::string& support_name) const;

  /// The named obstacle's contact; throws std::invalid_argument for an unknown name.
  ContactReport contact(const std::string& obstacle_name) const;

  /// Sum of all applied loads (body force and tractions), N. At equilibrium the reactions of all
  /// supports add up to minus this.
  Eigen::Vector3d total_applied_load() const;

  /// |sum of reactions + applied load| / max(|applied load|, largest |reaction|): ~1e-9 or less for
  /// a converged solve.
  double equilibrium_defect() const;

  /// ||u_h - u|| / ||u|| in L2 over the mesh (QGaussSimplex of degree + 2 points per direction).
  double relative_l2_error(const VectorField& exact) const;

  /// Largest |u_h - u| over all DoFs (nodal values).
  double max_nodal_error(const VectorField& exact) const;

  /// Writes `<basename>.pvtu` (+ one .vtu per rank) and `<basename>.pvd` into `directory`: the
  /// displacement, the partition and the Young's modulus, with P2 fields on subdivided patches.
  /// Returns the .pvd path.
  std::filesystem::path output_results(const std::filesystem::path& directory,
                                       const std::string& basename) const;

  /// Writes `<basename>.h5` (datasets `nodes`, `cells`, `displacement`; one file for all ranks,
  /// through parallel HDF5) and `<basename>.xdmf` naming it, into `directory`, for ParaView, VisIt
  /// or h5py. Nodes are the mesh vertices (a vertex on a partition boundary appears once per rank
  /// that owns a cell around it), cells the tetrahedra. The values are nodal, so P2 is written at
  /// its vertices only: patches with one subdivision, because deal.II 9.4.1's degree-2 HDF5 path
  /// corrupts the heap. Values carry single-precision round-off (deal.II 9.4 keeps patch data as
  /// float). Each file is written under a temporary name and renamed. Returns the .xdmf path.
  std::filesystem::path output_hdf5(const std::filesystem::path& directory,
                                    const std::string& basename) const;

  SolveStatistics statistics() const;

  /// Implementation (deal.II types), defined in the sources only.
  struct Implementation;

 private:
  std::unique_ptr<Implementation> impl_;
};

/// output_hdf5's files for a displacement given at the mesh vertices (a stored FEM result, as
/// `msfem run` has when its cache answered), written by the calling process alone.
std::filesystem::path write_vertex_displacement_hdf5(const VolumeMesh& mesh,
                                                     const Eigen::MatrixX3d& displacement,
                                                     const std::filesystem::path& directory,
                                                     const std::string& basename);

}  // namespace msfem::fem_reference
