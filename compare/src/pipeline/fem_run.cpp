#include "msfem/compare/pipeline/fem_run.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/cases/surface.hpp"
#include "msfem/cases/surface_refinement.hpp"
#include "msfem/fem_reference/errors.hpp"
#include "msfem/fem_reference/supports_and_loads.hpp"
#include "msfem/fem_reference/surface_mesher.hpp"

namespace msfem::compare {
namespace {

fem_reference::Preconditioner preconditioner_for(cases::FemSolver solver) {
  switch (solver) {
    case cases::FemSolver::mumps:
      return fem_reference::Preconditioner::mumps;
    case cases::FemSolver::cg_boomeramg:
      return fem_reference::Preconditioner::boomer_amg;
    case cases::FemSolver::cg_gamg:
      break;
  }
  return fem_reference::Preconditioner::gamg;
}

double mean_edge_length(const cases::Surface& s) {
  const auto edges = cases::unique_edges(s);
  double sum = 0;
  for (const auto& e : edges)
    sum += (s.vertices.row(e[0]) - s.vertices.row(e[1])).norm();
  return sum / static_cast<double>(edges.size());
}

// Refuses, before meshing, a cell size that would mesh for hours and not fit in memory: the cells
// a size gives (a regular tetrahedron of edge h has volume h³/6√2), the tools' refined balls too.
void check_mesh_cost(const Problem& problem, const fem_reference::MeshOptions& options) {
  const auto& p = problem.parameters;
  auto cells = [](double volume, double h) { return 6 * std::sqrt(2.0) * volume / (h * h * h); };
  double estimate = cells(std::abs(cases::signed_volume(problem.surface)), options.cell_size);
  for (const auto& r : options.refinements)
    estimate += cells(4.0 / 3.0 * M_PI * std::pow(r.radius, 3), r.cell_size);
  const double dofs = 3.0 * estimate / 5.5 * (p.fem.degree == 2 ? 8.0 : 1.0);
  if (dofs > max_reference_dofs) {
    char message[256];
    std::snprintf(message, sizeof message,
                  ": fem/cell size %.3g m would mesh about %.3g M tetrahedra (%.3g M DoFs at "
                  "P%d), above the %.3g M DoFs msfem solves; use a larger cell size",
                  options.cell_size, estimate * 1e-6, dofs * 1e-6, p.fem.degree,
                  max_reference_dofs * 1e-6);
    throw cases::InputError(p.file.string() + message);
  }
}

// The case's patch force as a uniform traction over the surface triangles whose centroids lie
// within its radius of the surface vertex farthest along its direction.
std::optional<fem_reference::Traction> patch_traction(const Problem& problem) {
  const auto& patch = problem.parameters.loads.patch_force;
  if (!patch.enabled) return std::nullopt;
  const int center = farthest_vertex(problem.surface, problem.centroid, patch.direction);
  const Eigen::Vector3d c = problem.surface.vertices.row(center).transpose();
  // Spread the total force as a uniform traction over the patch's area on the surface.
  double patch_area = 0;
  const auto& s = problem.surface;
  for (Eigen::Index t = 0; t < s.num_triangles(); ++t) {
    const Eigen::Vector3d a = s.vertices.row(s.triangles(t, 0)),
                          b = s.vertices.row(s.triangles(t, 1)),
                          d = s.vertices.row(s.triangles(t, 2));
    if (((a + b + d) / 3 - c).norm() <= patch.radius_m)
      patch_area += 0.5 * (b - a).cross(d - a).norm();
  }
  if (patch_area > 0) {
    fem_reference::Traction traction;
    traction.name = "patch";
    traction.region = fem_reference::ball(c, patch.radius_m);
    traction.traction = fem_reference::uniform_traction(patch.force_n / patch_area);
    return traction;
  }
  return std::nullopt;
}

}  // namespace

fem_reference::SphereObstacle tool_obstacle(const ToolPlacement& tool) {
  fem_reference::SphereObstacle sphere;
  sphere.name = "tool";
  sphere.center = tool.pushed_center();
  sphere.radius = tool.radius;
  sphere.push_direction = -tool.outward_normal;
  return sphere;
}

void check_no_rigid_motion(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                           const std::optional<ToolPlacement>& tool) {
  std::optional<fem_reference::Support> tool_support;
  if (tool && !tool->frictionless) tool_support = tool_patch_support(*tool);
  std::vector<Eigen::Vector3d> held;
  int fixed = 0;
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v) {
    const Eigen::Vector3d x = mesh.vertices.row(v).transpose();
    fixed += problem.fixed_region(x);
    if (problem.fixed_region(x) || (tool_support && tool_support->region(x))) held.push_back(x);
  }
  if (fixed == 0)
    throw cases::InputError(problem.parameters.file.string() +
                            ": support/fixed region: it catches no node of the FEM mesh; enlarge "
                            "it (or move it) so that it holds part of the body");
  double spread = 0.0;  // twice the largest triangle area among the held nodes, sampled
  if (held.size() >= 3) {
    const Eigen::Vector3d a = held.front();
    const auto far = *std::max_element(held.begin(), held.end(), [&](const auto& p, const auto& q) {
      return (p - a).squaredNorm() < (q - a).squaredNorm();
    });
    for (const auto& x : held)
      spread = std::max(spread, (far - a).cross(x - a).norm());
  }
  const Eigen::Vector3d extent =
      mesh.vertices.colwise().maxCoeff() - mesh.vertices.colwise().minCoeff();
  if (!(spread > 1e-6 * extent.squaredNorm()))
    throw cases::InputError(problem.parameters.file.string() + ": support/fixed region: it holds " +
                            std::to_string(held.size()) + " node(s) of the FEM mesh" +
                            (held.size() >= 3 ? ", all on one line" : "") +
                            ", so the body can move or turn freely and the FEM is singular; "
                            "enlarge the fixed region");
}

fem_reference::VolumeMesh mesh_problem(const Problem& problem,
                                       std::optional<std::vector<ToolPlacement>> refine_near) {
  const auto& p = problem.parameters;
  fem_reference::MeshOptions options;
  const double edge = mean_edge_length(problem.surface);
  options.cell_size = p.fem.cell_size_m > 0 ? p.fem.cell_size_m : edge;
  if (!refine_near && !problem.tools.empty()) refine_near = {problem.tools.front()};
  const std::vector<ToolPlacement> tools = refine_near.value_or(std::vector<ToolPlacement>{});
  std::optional<cases::Surface> refined;  // the case's own surface unless refined
  double tool_cell = 0.5 * options.cell_size;
  if (p.fem.refine_at_tool && !tools.empty()) {
    // The refined surface keeps the case's vertices first, so mesh vertex i is still surface
    // vertex i for every vertex the metrics compare.
    std::vector<cases::RefinementBall> balls;
    double radius = 0;
    for (const ToolPlacement& t : tools) {
      balls.push_back({t.contact_point, 2 * t.radius});
      radius = std::max(radius, t.radius);
    }
    tool_cell = p.fem.tool_cell_size_m > 0 ? p.fem.tool_cell_size_m : radius / 3;
    refined = cases::refine_near(problem.surface, balls, tool_cell).surface;
  }
  for (const ToolPlacement& t : tools)
    options.refinements.push_back(
        fem_reference::LocalRefinement{t.contact_point, 2 * t.radius, 2 * t.radius, tool_cell});
  check_mesh_cost(problem, options);
  const cases::Surface& surface = refined ? *refined : problem.surface;
  return fem_reference::mesh_closed_surface(surface.vertices, surface.triangles, options);
}

std::vector<bool> prescribed_surface_vertices(const Problem& problem,
                                              const std::optional<ToolPlacement>& tool) {
  const auto& s = problem.surface;
  std::vector<bool> prescribed(static_cast<std::size_t>(s.num_vertices()), false);
  std::optional<fem_reference::Support> tool_support;
  if (tool && !tool->frictionless) tool_support = tool_patch_support(*tool);
  for (Eigen::Index v = 0; v < s.num_vertices(); ++v) {
    const Eigen::Vector3d x = s.vertices.row(v).transpose();
    prescribed[v] = problem.fixed_region(x) || (tool_support && tool_support->region(x));
  }
  return prescribed;
}

FemSolution solve_fem(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                      const std::optional<ToolPlacement>& tool,
                      const fem_reference::VectorField& initial_displacement) {
  const auto& p = problem.parameters;
  check_no_rigid_motion(problem, mesh, tool);
  fem_reference::ElasticityModel model;
  model.degree = static_cast<unsigned>(p.fem.degree);
  model.material.youngs_modulus = p.material.youngs_modulus_pa;
  if (problem.youngs_modulus_image)
    model.material.youngs_modulus_field =
        [image = problem.youngs_modulus_image](const Eigen::Vector3d& x) { return (*image)(x); };
  model.material.poisson_ratio = p.material.poisson_ratio;
  model.material.density = p.material.density_kg_per_m3;
  model.material.gravity = p.loads.gravity_m_per_s2;
  model.solver.relative_tolerance = p.fem.relative_tolerance;
  model.initial_displacement = initial_displacement;
  model.solver.preconditioner = preconditioner_for(p.fem.solver);
  // The tool first: a node caught by both keeps the tool's displacement.
  if (tool && !tool->frictionless) model.supports.push_back(tool_patch_support(*tool));
  if (tool && tool->frictionless) model.obstacles.push_back(tool_obstacle(*tool));
  model.supports.push_back(fem_reference::fixed_support("fixed", problem.fixed_region));

  if (auto traction = patch_traction(problem)) model.tractions.push_back(*traction);

  FemSolution solution;
  solution.solver = cases::name_of(p.fem.solver);
  std::unique_ptr<fem_reference::ElasticityProblem> fem;
  try {
    fem = std::make_unique<fem_reference::ElasticityProblem>(mesh, model);
    fem->run();
  } catch (const fem_reference::SolverError& e) {
    // GAMG's smoothers can turn indefinite on a graded mesh (the tool refinement's); BoomerAMG
    // copes with those, so one failure does not end a long run or a calibration.
    if (model.solver.preconditioner != fem_reference::Preconditioner::gamg) throw;
    std::cerr << "msfem: " << e.what() << "; solving again with CG + BoomerAMG\n";
    model.solver.preconditioner = fem_reference::Preconditioner::boomer_amg;
    fem = std::make_unique<fem_reference::ElasticityProblem>(mesh, model);
    fem->run();
    solution.solver = "cg_boomeramg (cg_gamg failed: " + std::string(e.what()) + ")";
    // A fallback's answer is trusted only if it is in equilibrium.
    if (!(fem->equilibrium_defect() < 1e-6))
      throw fem_reference::SolverError(
          "the FEM reference is not in equilibrium after the BoomerAMG fallback (|Σ reactions + "
          "loads| / |loads| = " +
          std::to_string(fem->equilibrium_defect()) + "): " + e.what());
  } catch (const fem_reference::FemError& e) {
    // A contact that cycles or does not settle: which load, in the case's words.
    if (!tool || !tool->frictionless) throw;
    throw fem_reference::FemError(p.file.string() + ": loads/tool at depth " +
                                  std::to_string(tool->depth) + " m: " + e.what());
  } catch (const std::invalid_argument& e) {
    // The FEM's own input checks (a support or traction that catches nothing) in the case's words.
    const std::string what = e.what();
    const char* key = what.find("'tool'") != std::string::npos    ? "loads/tool"
                      : what.find("'fixed'") != std::string::npos ? "support/fixed region"
                      : what.find("'patch'") != std::string::npos ? "loads/patch force"
                                                                  : "fem";
    throw cases::InputError(p.file.string() + ": " + key + ": " + what);
  }
  const fem_reference::ElasticityProblem& fem_solved = *fem;
  solution.vertex_displacement = fem_solved.vertex_displacements();
  solution.surface_displacement =
      solution.vertex_displacement.topRows(problem.surface.num_vertices());
  if (tool && tool->frictionless) {
    solution.contact = fem_solved.contact("tool");
    solution.tool_force = -solution.contact->force;
  } else if (tool) {
    solution.tool_force = -fem_solved.reaction_force("tool");
  }
  solution.statistics = fem_solved.statistics();
  solution.volume_change = volume_change(problem.surface, solution.surface_displacement);
  return solution;
}

}  // namespace msfem::compare
