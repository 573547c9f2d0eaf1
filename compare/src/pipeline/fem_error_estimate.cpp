#include "msfem/compare/pipeline/fem_error_estimate.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <unordered_set>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/compare/pipeline/metrics.hpp"
#include "msfem/fem_reference/point_locator.hpp"

namespace msfem::compare {
namespace {

using ErrorEstimate = cases::FemParameters::ErrorEstimate;

struct MeshCounts {
  std::size_t vertices = 0, edges = 0, faces = 0, cells = 0;
};

MeshCounts count_entities(const fem_reference::VolumeMesh& mesh) {
  const auto n = std::uint64_t(mesh.num_vertices());
  std::unordered_set<std::uint64_t> edges;
  std::unordered_set<std::uint64_t> faces;
  // Three ids packed in 64 bits hold below 2.6 M vertices; a larger mesh's second solve is far
  // above max_estimate_dofs whatever its exact count (a tetrahedral mesh has about 7 edges and 12
  // faces per vertex).
  if (n > 2'000'000)
    return {std::size_t(n), std::size_t(7 * n), std::size_t(12 * n),
            std::size_t(mesh.num_tetrahedra())};
  for (Eigen::Index e = 0; e < mesh.num_tetrahedra(); ++e) {
    std::array<std::uint64_t, 4> v;
    for (int k = 0; k < 4; ++k)
      v[std::size_t(k)] = std::uint64_t(mesh.tetrahedra(e, k));
    std::sort(v.begin(), v.end());
    for (std::size_t a = 0; a < 4; ++a)
      for (std::size_t b = a + 1; b < 4; ++b) {
        edges.insert(v[a] * n + v[b]);
        for (std::size_t c = b + 1; c < 4; ++c)
          faces.insert((v[a] * n + v[b]) * n + v[c]);
      }
  }
  return {std::size_t(n), edges.size(), faces.size(), std::size_t(mesh.num_tetrahedra())};
}

// Vector DoFs of simplex P1 or P2 on the mesh, or on its uniform refinement (each edge gives a
// vertex; each edge two edges, each face three, each cell one across its inner octahedron).
std::size_t vector_dofs(const MeshCounts& m, int degree, bool refined) {
  MeshCounts f = m;
  if (refined) f = {m.vertices + m.edges, 2 * m.edges + 3 * m.faces + m.cells, 0, 8 * m.cells};
  return 3 * (degree == 1 ? f.vertices : f.vertices + f.edges);
}

// A displacement given at the mesh's vertices, linear in each tetrahedron.
fem_reference::VectorField interpolant(const fem_reference::VolumeMesh& mesh,
                                       const Eigen::MatrixX3d& vertex_displacement) {
  auto locator = std::make_shared<const fem_reference::PointLocator>(mesh);
  return
      [locator, tetrahedra = mesh.tetrahedra, u = vertex_displacement](const Eigen::Vector3d& x) {
        const fem_reference::PointLocation at = locator->locate(x);
        Eigen::Vector3d value = Eigen::Vector3d::Zero();
        for (int k = 0; k < 4; ++k)
          value += at.barycentric[k] * u.row(tetrahedra(at.cell, k)).transpose();
        return value;
      };
}

std::string text(const char* format, double a, double b = 0, double c = 0) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, format, a, b, c);
  return buffer;
}

}  // namespace

namespace {

// Degree 1 on the reference's own mesh: a seventh of a P2 reference's DoFs, so every degree-2 run
// can afford it. The P2 answer is the more accurate of the two, so their difference bounds its
// error from above (and flags more variants as unresolved, never fewer).
ErrorEstimatePlan lower_degree_plan(const MeshCounts& counts, int loads, const std::string& why) {
  ErrorEstimatePlan plan;
  plan.method = ErrorEstimate::lower_degree;
  plan.predicted_dofs = vector_dofs(counts, 1, false);
  plan.loads = loads;
  plan.note = "lower_degree, P1 on the same mesh: an upper bound on the reference's error" + why;
  return plan;
}

}  // namespace

ErrorEstimatePlan plan_error_estimate(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                                      int reference_solves, int loads) {
  const auto& fem = problem.parameters.fem;
  ErrorEstimatePlan plan;
  if (fem.error_estimate == ErrorEstimate::none) {
    plan.note = "not estimated (fem/error estimate = none)";
    return plan;
  }
  const bool automatic = fem.error_estimate == ErrorEstimate::automatic;
  const MeshCounts counts = count_entities(mesh);
  if (fem.error_estimate == ErrorEstimate::lower_degree)
    return lower_degree_plan(counts, loads, "");
  const std::size_t reference_dofs = vector_dofs(counts, fem.degree, false);
  const bool degree = fem.error_estimate == ErrorEstimate::degree || (automatic && fem.degree == 1);
  plan.method = degree ? ErrorEstimate::degree : ErrorEstimate::refine;
  plan.predicted_dofs =
      degree ? vector_dofs(counts, 2, false) : vector_dofs(counts, fem.degree, true);
  const std::string what = degree ? "P2 on the same mesh" : "the mesh refined once";
  if (plan.predicted_dofs > max_estimate_dofs) {
    const std::string why = text("%.3g M DoFs with ", plan.predicted_dofs * 1e-6) + what +
                            text(", above the %.3g M msfem attempts", max_estimate_dofs * 1e-6);
    if (!automatic)
      throw cases::InputError(problem.parameters.file.string() + ": fem/error estimate = " +
                              cases::name_of(plan.method) + ": the second solve would have " + why +
                              "; use a larger fem/cell size or error estimate = none");
    if (fem.degree == 2)
      return lower_degree_plan(counts, loads, " (auto: a refined solve would have " + why + ")");
    plan.method = ErrorEstimate::none;
    plan.note = "not estimated: the second solve would have " + why +
                " (a larger fem/cell size gives an estimate)";
    return plan;
  }
  plan.loads = loads;
  plan.note = (automatic ? "auto: " : "") + cases::name_of(plan.method) + ", " + what;
  // One second solve costs about twice its DoF ratio in reference solves (CG needs more
  // iterations on the finer mesh: 16x for 7.4x the DoFs on the sphere, 13x for 7.3x on the brain).
  // auto keeps the estimate within 3x the reference's own solves, except on problems small enough
  // to take seconds either way.
  const double cost_ratio = 2.0 * double(plan.predicted_dofs) / double(reference_dofs);
  const double budget = 3.0 * reference_solves;
  const bool small = plan.predicted_dofs * std::size_t(loads) <= 600'000;
  if (automatic && !degree && !small && cost_ratio * loads > budget) {
    plan.loads = std::min(int(budget / cost_ratio), loads);
    const std::string cost = text(
        "each second solve costs about %.0f reference solves, and auto keeps within 3x the "
        "reference's %.0f (fem/error estimate = refine estimates every load)",
        cost_ratio, reference_solves);
    if (plan.loads == 0) return lower_degree_plan(counts, loads, " (auto: " + cost + ")");
    plan.note += text(", the first %.0f of %.0f loads: ", plan.loads, loads) + cost;
  }
  return plan;
}

FemErrorEstimate estimate_fem_error(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                                    const ErrorEstimatePlan& plan,
                                    const std::vector<const FemSolution*>& references,
                                    const std::vector<std::vector<int>>& compared,
                                    const std::vector<std::optional<ToolPlacement>>& tools) {
  FemErrorEstimate e;
  e.method = cases::name_of(plan.method);
  e.note = plan.note;
  e.loads.resize(references.size());
  if (plan.method == ErrorEstimate::none) return e;
  const auto start = std::chrono::steady_clock::now();
  Problem second_problem = problem;
  // The estimate is a difference of a few per cent: a residual of 1e-7 resolves it, and saves a
  // third of the second solve's iterations over the reference's 1e-10.
  auto& tolerance = second_problem.parameters.fem.relative_tolerance;
  tolerance = std::max(tolerance, 1e-7);
  fem_reference::VolumeMesh refined;
  if (plan.method == ErrorEstimate::refine)
    refined = fem_reference::refine_uniformly(mesh);
  else
    second_problem.parameters.fem.degree = plan.method == ErrorEstimate::lower_degree ? 1 : 2;
  // Which of the two solves is the more accurate: the second, except for lower_degree.
  const bool second_is_finer = plan.method != ErrorEstimate::lower_degree;
  const fem_reference::VolumeMesh& second_mesh =
      plan.method == ErrorEstimate::refine ? refined : mesh;
  const std::vector<int> patch = patch_vertices(problem);
  const int n = std::min<int>(plan.loads, int(references.size()));
  for (int k = 0; k < n; ++k) {
    const FemSolution& reference = *references[std::size_t(k)];
    // A frictionless tool's second contact starts from the reference's answer: about half the
    // active-set iterations of a start from Hertz's radius, each a solve on the larger mesh.
    const auto& tool = tools[std::size_t(k)];
    const FemSolution second =
        solve_fem(second_problem, second_mesh, tool,
                  tool && tool->frictionless ? interpolant(mesh, reference.vertex_displacement)
                                             : fem_reference::VectorField());
    const FemSolution& coarse = second_is_finer ? reference : second;
    const FemSolution& fine = second_is_finer ? second : reference;
    e.dofs = second.statistics.dofs;
    LoadErrorEstimate& load = e.loads[std::size_t(k)];
    load.rel_l2_error = displacement_error(coarse.surface_displacement, fine.surface_displacement,
                                           compared[std::size_t(k)])
                            .rel_l2_error;
    if (tools[std::size_t(k)]) {
      load.force_rel_error = reaction_force_rel_error(coarse.tool_force, fine.tool_force);
    } else if (!patch.empty()) {
      const Eigen::Vector3d f = mean_displacement(fine.surface_displacement, patch);
      load.force_rel_error =
          (mean_displacement(coarse.surface_displacement, patch) - f).norm() / f.norm();
    }
  }
  e.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return e;
}

}  // namespace msfem::compare
