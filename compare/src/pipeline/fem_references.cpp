#include "msfem/compare/pipeline/fem_references.hpp"

#include <algorithm>
#include <cstdio>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/surface.hpp"
#include "msfem/compare/pipeline/fem_cache.hpp"
#include "msfem/compare/pipeline/ranks.hpp"
#include "msfem/fem_reference/volume_mesh.hpp"

namespace msfem::compare {
namespace {

// The FEM pressed to each depth of the curve; the load's own depth is already solved.
std::vector<ForceDepthPoint> fem_force_depth(const Problem& problem,
                                             const fem_reference::VolumeMesh& mesh,
                                             const LoadReference& load,
                                             const std::vector<double>& depths,
                                             const Progress& progress) {
  std::vector<ForceDepthPoint> curve;
  const auto start = Clock::now();
  for (std::size_t i = 0; i < depths.size(); ++i) {
    const FemSolution s = depths[i] == load.tool->depth
                              ? load.fem
                              : solve_fem(problem, mesh, at_depth(*load.tool, depths[i]));
    curve.push_back({depths[i], s.tool_force, std::nullopt, s.contact});
    progress.advance("FEM force-depth curve", static_cast<int>(i + 1),
                     static_cast<int>(depths.size()), seconds_since(start));
  }
  return curve;
}

// Every load's entry, where the cache holds it, and the mesh they share.
std::vector<std::optional<FemCacheEntry>> cached_entries(FemReferences& r,
                                                         const ReferenceRequest& request) {
  std::vector<std::optional<FemCacheEntry>> cached(r.loads.size());
  if (!request.cache_directory) return cached;
  for (std::size_t i = 0; i < r.loads.size(); ++i) {
    cached[i] = load_fem_cache(*request.cache_directory, r.loads[i].cache_key);
    // The ranks solve together, so a load is taken from the cache only where every rank's cache
    // (each node's own disk on a cluster) holds it.
    if (!ranks::on_every_rank(cached[i].has_value())) cached[i].reset();
    if (cached[i] && r.mesh.num_tetrahedra() == 0) r.mesh = cached[i]->mesh;
  }
  return cached;
}

void take_cached(FemReferences& r, std::vector<std::optional<FemCacheEntry>>& cached) {
  for (std::size_t i = 0; i < r.loads.size(); ++i) {
    if (!cached[i]) continue;
    LoadReference& load = r.loads[i];
    load.fem = std::move(cached[i]->solution);
    load.force_depth = std::move(cached[i]->force_depth);
    const FemErrorEstimate& e = cached[i]->error_estimate;
    if (!e.loads.empty()) load.fem_error = e.loads.front();
    if (r.solved == 0) r.estimate = {e.method, e.note, e.dofs, e.time_s, {}};
    load.from_cache = true;
    ++r.from_cache;
  }
}

// Solves the loads the cache did not hold, estimates the reference's own error there, and stores
// each with its estimate.
void solve_fresh(const Problem& problem, FemReferences& r, const ReferenceRequest& request,
                 const std::vector<std::optional<FemCacheEntry>>& cached,
                 const Progress& progress) {
  std::vector<std::size_t> fresh;
  for (std::size_t i = 0; i < r.loads.size(); ++i)
    if (!cached[i]) fresh.push_back(i);
  if (fresh.empty()) return;
  // Decided (and refused, for a method that cannot run) before the first solve.
  const ErrorEstimatePlan plan =
      plan_error_estimate(problem, r.mesh, request.planned_solves, static_cast<int>(fresh.size()));
  progress.stage("solving the FEM reference (P" + std::to_string(problem.parameters.fem.degree) +
                 ", " + std::to_string(r.mesh.num_tetrahedra()) + " tetrahedra) at " +
                 std::to_string(fresh.size()) + " of " + std::to_string(r.loads.size()) +
                 (r.loads.size() == 1 ? " load" : " loads"));
  const auto start = Clock::now();
  std::vector<const FemSolution*> solutions;
  std::vector<std::vector<int>> compared;
  std::vector<std::optional<ToolPlacement>> tools;
  for (std::size_t k = 0; k < fresh.size(); ++k) {
    LoadReference& load = r.loads[fresh[k]];
    load.fem = solve_fem(problem, r.mesh, load.tool);
    if (fresh[k] == 0 && load.tool)
      load.force_depth = fem_force_depth(problem, r.mesh, load, request.curve_depths, progress);
    ++r.solved;
    progress.advance("FEM reference per load", static_cast<int>(k + 1),
                     static_cast<int>(fresh.size()), seconds_since(start));
    solutions.push_back(&load.fem);
    compared.push_back(load.compared_vertices);
    tools.push_back(load.tool);
  }
  if (plan.method != cases::FemParameters::ErrorEstimate::none)
    progress.stage("estimating the reference's own error (" + plan.note + ")");
  const FemErrorEstimate estimate =
      estimate_fem_error(problem, r.mesh, plan, solutions, compared, tools);
  r.estimate = {estimate.method, estimate.note, estimate.dofs, estimate.time_s, {}};
  for (std::size_t k = 0; k < fresh.size(); ++k) {
    LoadReference& load = r.loads[fresh[k]];
    if (k < estimate.loads.size()) load.fem_error = estimate.loads[k];
    if (!request.cache_directory) continue;
    FemErrorEstimate one = r.estimate;
    one.loads = {load.fem_error};
    store_fem_cache(*request.cache_directory, load.cache_key,
                    {r.mesh, load.fem, load.force_depth, one});
  }
}

// A load that moves the surface by more than half the model's smallest extent (the estimates in
// make_problem let through what they cannot size: a soft image, a support far from the load) is
// outside small-strain elasticity: the reference, and any error measured against it, says nothing.
void check_small_strain(const Problem& problem, const FemReferences& r) {
  const Eigen::Matrix<double, 2, 3> box = cases::bounding_box(problem.surface);
  const double extent = (box.row(1) - box.row(0)).minCoeff();
  for (std::size_t i = 0; i < r.loads.size(); ++i) {
    const double moved = r.loads[i].fem.surface_displacement.rowwise().norm().maxCoeff();
    if (moved <= 0.5 * extent) continue;
    char text[400];
    std::snprintf(text, sizeof text,
                  ": the FEM reference moves the surface %.3g m at load %zu, more than half the "
                  "model's smallest extent (%.3g m): outside the small strains linear elasticity "
                  "holds for (loads/gravity, loads/patch force/force, material/youngs modulus)",
                  moved, i + 1, extent);
    throw cases::InputError(problem.parameters.file.string() + text);
  }
}

}  // namespace

std::vector<int> unprescribed_vertices(const Problem& problem,
                                       const std::optional<ToolPlacement>& tool) {
  std::vector<int> free;
  const std::vector<bool> prescribed = prescribed_surface_vertices(problem, tool);
  for (std::size_t v = 0; v < prescribed.size(); ++v)
    if (!prescribed[v]) free.push_back(static_cast<int>(v));
  if (free.empty())
    throw cases::InputError(problem.parameters.file.string() +
                            ": every surface vertex is prescribed");
  return free;
}

FemReferences fem_references(const Problem& problem, const ReferenceRequest& request,
                             const Progress& progress) {
  FemReferences r;
  for (std::size_t i = 0; i < request.loads.size(); ++i) {
    LoadReference load;
    load.tool = request.loads[i];
    load.compared_vertices = unprescribed_vertices(problem, load.tool);
    load.cache_key = fem_cache_key(problem, request.refine_near, load.tool,
                                   i == 0 ? request.curve_depths : std::vector<double>{});
    r.loads.push_back(std::move(load));
  }
  std::vector<std::optional<FemCacheEntry>> cached = cached_entries(r, request);
  if (r.mesh.num_tetrahedra() == 0) {
    progress.stage("meshing the volume (Gmsh) for the FEM reference, refined near " +
                   std::to_string(request.refine_near.size()) + " tool position(s)");
    r.mesh = mesh_problem(problem, request.refine_near);
  }
  check_no_rigid_motion(problem, r.mesh, request.loads.empty() ? std::nullopt : request.loads[0]);
  const bool all_cached =
      std::all_of(cached.begin(), cached.end(), [](const auto& e) { return e; });
  if (all_cached && !r.loads.empty())
    progress.stage("FEM reference from the cache (" + request.cache_directory->string() +
                   "): nothing it depends on changed");
  solve_fresh(problem, r, request, cached, progress);
  take_cached(r, cached);
  check_small_strain(problem, r);
  if (r.mesh.num_tetrahedra() > 0)
    r.worst_cell_quality = fem_reference::cell_quality(r.mesh).minCoeff();
  return r;
}

}  // namespace msfem::compare
