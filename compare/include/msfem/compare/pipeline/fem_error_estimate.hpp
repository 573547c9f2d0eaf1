#pragma once
// The FEM reference's own discretisation error: each load solved a second time on a finer space
// (the mesh with every tetrahedron split into eight, or one degree higher on the same mesh), and
// the difference taken at what the harness compares. A spring variant whose error is within a few
// times this is not resolved by the reference: the table cannot tell its error from the FEM's.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "msfem/compare/pipeline/fem_run.hpp"
#include "msfem/compare/pipeline/problem.hpp"

namespace msfem::compare {

/// The reference's estimated error at one load.
struct LoadErrorEstimate {
  std::optional<double> rel_l2_error;  ///< displacement at the load's compared vertices
  /// Tool force; with a patch force and no tool, the patch's mean displacement; none for gravity
  /// alone (no force is measured).
  std::optional<double> force_rel_error;
};

struct FemErrorEstimate {
  std::string method = "none";  ///< refine | degree | none: what was solved
  std::string note;             ///< how the method was chosen and what it left out
  std::size_t dofs = 0;         ///< of one second solve
  double time_s = 0.0;          ///< of all second solves
  /// One per load in the run's load order (tool 0, 1, ...; one load without a tool); loads the
  /// budget left out have no values.
  std::vector<LoadErrorEstimate> loads;
};

/// What the estimate will solve, decided before any solve from the mesh and the case.
struct ErrorEstimatePlan {
  /// refine, degree or none (never automatic: the plan is what auto chose).
  cases::FemParameters::ErrorEstimate method = cases::FemParameters::ErrorEstimate::none;
  int loads = 0;                   ///< the first `loads` loads are estimated
  std::size_t predicted_dofs = 0;  ///< of one second solve
  std::string note;
};

/// Largest second solve (DoFs) the estimate attempts: about 12 GB with PETSc's AMG, half of the
/// machines msfem is built for.
inline constexpr std::size_t max_estimate_dofs = 4'000'000;

/// The plan for fem/error estimate on this mesh, with `reference_solves` solves of the reference
/// itself (the loads and the force-depth curve) and `loads` loads. Throws cases::InputError (naming
/// the case file and key) when the case asks for a method that cannot run here.
ErrorEstimatePlan plan_error_estimate(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                                      int reference_solves, int loads);

/// Runs the plan. `references[k]` is load k's reference solution, `compared[k]` its compared
/// vertices, `tools[k]` its tool (none without a tool).
FemErrorEstimate estimate_fem_error(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                                    const ErrorEstimatePlan& plan,
                                    const std::vector<const FemSolution*>& references,
                                    const std::vector<std::vector<int>>& compared,
                                    const std::vector<std::optional<ToolPlacement>>& tools);

/// Whether an error of `variant_error` is within `factor` times the reference's own `estimate`
/// (the variant is then not resolved by this reference).
inline bool within_reference_error(double variant_error, const std::optional<double>& estimate,
                                   double factor = 3.0) {
  return estimate && variant_error <= factor * *estimate;
}

}  // namespace msfem::compare
