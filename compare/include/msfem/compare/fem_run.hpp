#pragma once
// The FEM reference on a problem: one volume mesh, one solve per tool placement (or per load).

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "msfem/compare/problem.hpp"
#include "msfem/fem_reference/elasticity_problem.hpp"
#include "msfem/fem_reference/volume_mesh.hpp"

namespace msfem::compare {

/// The tetrahedral mesh of the problem's surface (its vertices kept as mesh vertices 0..n-1), sized
/// by fem/cell size and refined near the given tools (none given: near the first of the problem's).
fem_reference::VolumeMesh mesh_problem(
    const Problem& problem, std::optional<std::vector<ToolPlacement>> refine_near = std::nullopt);

struct FemSolution {
  Eigen::MatrixX3d surface_displacement;                 ///< n_surface x 3, m
  Eigen::MatrixX3d vertex_displacement;                  ///< every mesh vertex, m
  Eigen::Vector3d tool_force = Eigen::Vector3d::Zero();  ///< force the tissue exerts on the tool, N
  double volume_change = 0.0;  ///< deformed / rest enclosed volume − 1 of the surface
  fem_reference::SolveStatistics statistics;
  std::string solver;  ///< the solver that produced it (the case's, or the fallback and why)
};

/// Solves the problem's FEM for `tool` (none: gravity and patch force only).
FemSolution solve_fem(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                      const std::optional<ToolPlacement>& tool);

/// Surface vertices that a support or the tool prescribes (excluded from the error metrics).
std::vector<bool> prescribed_surface_vertices(const Problem& problem,
                                              const std::optional<ToolPlacement>& tool);

}  // namespace msfem::compare
