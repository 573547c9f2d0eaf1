#pragma once
// The FEM reference on a problem: one volume mesh, one solve per tool placement (or per load).

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "msfem/compare/pipeline/problem.hpp"
#include "msfem/fem_reference/elasticity_problem.hpp"
#include "msfem/fem_reference/volume_mesh.hpp"

namespace msfem::compare {

/// The largest reference msfem meshes and solves (estimated from the volume and cell sizes before
/// meshing): 6 M DoFs, about 20 GB with PETSc's AMG.
inline constexpr double max_reference_dofs = 6e6;

/// The tetrahedral mesh of the problem's surface (its vertices kept as mesh vertices 0..n-1), sized
/// by fem/cell size and refined near the given tools (none given: near the first of the problem's).
/// Throws cases::InputError, before meshing, when the cell sizes would give more than
/// max_reference_dofs.
fem_reference::VolumeMesh mesh_problem(
    const Problem& problem, std::optional<std::vector<ToolPlacement>> refine_near = std::nullopt);

struct FemSolution {
  Eigen::MatrixX3d surface_displacement;                 ///< n_surface x 3, m
  Eigen::MatrixX3d vertex_displacement;                  ///< every mesh vertex, m
  Eigen::Vector3d tool_force = Eigen::Vector3d::Zero();  ///< force the tissue exerts on the tool, N
  double volume_change = 0.0;  ///< deformed / rest enclosed volume − 1 of the surface
  fem_reference::SolveStatistics statistics;
  /// With a frictionless tool: its contact (force, active nodes, radius, penetration).
  std::optional<fem_reference::ContactReport> contact;
  std::string solver;  ///< the solver that produced it (the case's, or the fallback and why)
};

/// Throws cases::InputError naming the case file and support/fixed region when the fixed region
/// catches no node of `mesh`, or the held nodes (fixed, and the tool's) leave the body free to move
/// or turn: the stiffness matrix would be singular, and an iterative solver returns garbage
/// instead of failing. solve_fem checks it; a command checks it once before its first solve.
void check_no_rigid_motion(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                           const std::optional<ToolPlacement>& tool);

/// The frictionless tool as the FEM's rigid sphere, named "tool": every boundary node a candidate.
fem_reference::SphereObstacle tool_obstacle(const ToolPlacement& tool);

/// Solves the problem's FEM for `tool` (none: gravity and patch force only). A frictionless tool's
/// contact iteration starts from `initial_displacement` when given (a coarser solve's answer).
FemSolution solve_fem(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                      const std::optional<ToolPlacement>& tool,
                      const fem_reference::VectorField& initial_displacement = {});

/// Surface vertices that a support or the tool prescribes (excluded from the error metrics).
std::vector<bool> prescribed_surface_vertices(const Problem& problem,
                                              const std::optional<ToolPlacement>& tool);

}  // namespace msfem::compare
