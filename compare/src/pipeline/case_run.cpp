#include "msfem/compare/pipeline/case_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <thread>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/compare/pipeline/fem_cache.hpp"
#include "msfem/fem_reference/volume_mesh.hpp"

namespace msfem::compare {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

nlohmann::json variant_parameters(const massspring::MassSpringModel& model) {
  const auto& n = model.network();
  nlohmann::json groups = nlohmann::json::object();
  for (std::size_t g = 0; g < n.spring_group_names.size(); ++g) {
    double k = 0, d = 0;
    int count = 0;
    for (int i = 0; i < n.num_springs(); ++i)
      if (n.spring_group[i] == static_cast<int>(g)) {
        k += n.stiffness[i];
        d += n.damping[i];
        ++count;
      }
    groups[n.spring_group_names[g]] = {{"springs", count},
                                       {"mean_stiffness_n_per_m", count ? k / count : 0.0},
                                       {"mean_damping_n_s_per_m", count ? d / count : 0.0}};
  }
  nlohmann::json parameters = {{"spring_groups", groups},
                               {"total_mass_kg", n.masses.sum()},
                               {"anchors", n.num_anchors()},
                               {"constrained_nodes", model.constrained_nodes().size()}};
  if (const auto& volume = model.volume())
    parameters["volume_preservation"] = {{"elements", volume->elements().num_elements()},
                                         {"mean_modulus_pa", volume->elements().modulus.mean()}};
  return parameters;
}

std::string millimetres(double metres) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g mm", metres * 1e3);
  return text;
}

double lateral_fraction(const Eigen::Vector3d& force, const Eigen::Vector3d& outward) {
  const double axial = force.dot(outward);
  return axial > 0 ? (force - axial * outward).norm() / axial : 0.0;
}

// Where and how a variant gives way under the tool, with the evidence where the variant has volume
// elements: edge springs keep a tetrahedron's edge lengths but not its orientation, so one turned
// inside out costs nothing more than its mirror image and the network gives way under the tool.
// None when it does not. The FEM's lateral reaction at full depth sets how sideways is too far.
std::optional<std::string> buckling_warning(const std::vector<ForceDepthPoint>& curve,
                                            const ToolPlacement& tool, const FemSolution& fem,
                                            Eigen::Index elements) {
  const double fem_fraction = lateral_fraction(fem.tool_force, tool.outward_normal);
  const double allowed = std::max(0.5, fem_fraction + lateral_fraction_margin);
  const BucklingOnset onset = buckling_onset(curve, tool, allowed);
  if (!onset.force_falls_at_m && !onset.turns_sideways_at_m) return std::nullopt;
  std::string why = std::string(buckling_warning_start) + ":";
  if (onset.force_falls_at_m)
    why += " from " + millimetres(*onset.force_falls_at_m) + " of " + millimetres(tool.depth) +
           " the reaction force stops growing with depth;";
  if (onset.turns_sideways_at_m) {
    char text[160];
    std::snprintf(text, sizeof text,
                  " from %s the equilibrium turns sideways (lateral reaction %.2f of the axial, "
                  "above %.2f; the FEM's is %.2f);",
                  millimetres(*onset.turns_sideways_at_m).c_str(), onset.lateral_fraction, allowed,
                  fem_fraction);
    why += text;
  }
  const auto first_inverted = std::find_if(curve.begin(), curve.end(), [](const auto& pt) {
    return pt.inverted_elements.value_or(0) > 0;
  });
  if (first_inverted != curve.end()) {
    const auto worst =
        std::max_element(curve.begin(), curve.end(), [](const auto& a, const auto& b) {
          return a.inverted_elements.value_or(0) < b.inverted_elements.value_or(0);
        });
    why += " " + std::to_string(*first_inverted->inverted_elements) + " of " +
           std::to_string(elements) + " tetrahedra are inverted at " +
           millimetres(first_inverted->depth_m) +
           (worst == first_inverted ? ""
                                    : ", " + std::to_string(*worst->inverted_elements) + " at " +
                                          millimetres(worst->depth_m)) +
           " (edge springs do not resist a tetrahedron turning inside out);";
  } else {
    why += " a spring network has no resistance to buckling or inverted elements;";
  }
  return why + " its force-depth curve is not one a haptic device should render";
}

// The surface vertices that neither a support nor the tool prescribes: the ones compared.
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

// How many solves the case's reference takes as `msfem run` makes it: each tool position, and the
// force-depth curve's depths other than the case's. Independent of what one command skips, so
// that the error estimate's method (and the cache entry) is the same for every command.
int reference_solve_count(const Problem& problem) {
  if (problem.tools.empty()) return 1;
  const auto& tool = problem.parameters.loads.tool;
  const auto depths = curve_depths(tool);
  return static_cast<int>(problem.tools.size()) +
         static_cast<int>(std::count_if(depths.begin(), depths.end(),
                                        [&](double d) { return d != tool.depth_m; }));
}

std::vector<ForceDepthPoint> fem_force_depth(const Problem& problem,
                                             const fem_reference::VolumeMesh& mesh,
                                             const FemSolution& at_depth_solution,
                                             const std::optional<ToolPlacement>& tool,
                                             const std::vector<double>& depths,
                                             const Progress& progress) {
  std::vector<ForceDepthPoint> curve;
  const auto start = Clock::now();
  for (std::size_t i = 0; i < depths.size(); ++i) {
    // The run's own depth is already solved.
    const FemSolution s = depths[i] == tool->depth
                              ? at_depth_solution
                              : solve_fem(problem, mesh, at_depth(*tool, depths[i]));
    curve.push_back({depths[i], s.tool_force, std::nullopt, s.contact});
    progress.advance("FEM force-depth curve", static_cast<int>(i + 1),
                     static_cast<int>(depths.size()), seconds_since(start));
  }
  return curve;
}

FemErrorEstimate estimate_run_error(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                                    const ErrorEstimatePlan& plan, const FemSolution& first,
                                    const std::vector<FemSolution>& others) {
  std::vector<const FemSolution*> references = {&first};
  std::vector<std::optional<ToolPlacement>> tools = {
      problem.tools.empty() ? std::nullopt : std::optional<ToolPlacement>(problem.tools.front())};
  for (std::size_t t = 0; t < others.size(); ++t) {
    references.push_back(&others[t]);
    tools.emplace_back(problem.tools[t + 1]);
  }
  std::vector<std::vector<int>> compared;
  for (const auto& tool : tools)
    compared.push_back(unprescribed_vertices(problem, tool));
  return estimate_fem_error(problem, mesh, plan, references, compared, tools);
}

// The variant's equilibrium with `tool` at its depth. With a path, a quasi-static loading path,
// each depth started from the last, as a tool pressed in steps is: a network with several
// equilibria (one that buckles under the tool) then stays on the branch a simulator would follow.
// Every step is a point of `curve` (a fall between two curve depths must not go unseen). The path
// ends at the tool's depth; the variant is left pressed there.
StaticSolution press(BuiltVariant& built, const std::optional<ToolPlacement>& tool,
                     const std::vector<double>& path, std::vector<ForceDepthPoint>& curve) {
  if (!tool || path.empty()) {
    if (tool) set_tool_depth(built, *tool);
    return solve_variant_static(built);
  }
  StaticSolution s;
  Eigen::VectorXd x;
  for (double depth : path) {
    set_tool_depth(built, at_depth(*tool, depth));
    StaticSolution at = solve_variant_static(built, x);
    x = at.x;
    curve.push_back({depth, at.tool_force, inverted_tetrahedra(built, at.x), {}});
    if (depth == tool->depth) s = std::move(at);
  }
  set_tool_depth(built, *tool);
  return s;
}

// The variant's equilibrium `s` (reached along `curve`) against the FEM's at the same tool: the
// same metrics for the run's own tool and for every other one.
ToolLoadVariant compare_at_tool(const Problem& problem, const BuiltVariant& built,
                                const StaticSolution& s, std::vector<ForceDepthPoint> curve,
                                const FemSolution& fem, const std::vector<int>& compared,
                                const std::optional<ToolPlacement>& tool) {
  ToolLoadVariant o;
  o.kind = built.kind;
  o.name = built.name;
  o.errors = zoned_displacement_error(
      s.surface_displacement, fem.surface_displacement, problem.surface.vertices, compared,
      tool ? tool->contact_point : problem.centroid, tool ? 2 * tool->radius : 0.0);
  o.tool_force = s.tool_force;
  if (tool) o.reaction_force_rel_error = reaction_force_rel_error(s.tool_force, fem.tool_force);
  o.volume_change = volume_change(problem.surface, s.surface_displacement);
  o.inverted_elements = inverted_tetrahedra(built, s.x);
  o.force_depth_monotone = force_grows_with_depth(curve, tool);
  o.force_depth = std::move(curve);
  const std::vector<int> patch = patch_vertices(problem);
  if (!patch.empty()) {
    const Eigen::Vector3d reference = mean_displacement(fem.surface_displacement, patch);
    o.patch_mean_displacement = mean_displacement(s.surface_displacement, patch);
    o.patch_displacement_rel_error =
        (*o.patch_mean_displacement - reference).norm() / reference.norm();
  }
  return o;
}

// The variant at each of the case's other tool positions, along the same loading path. Two
// workers (each with its own copy of the network) share the tools: the statics are independent
// and a machine with two cores finishes the brain's four tools in about half the time. The
// timing is over by now, so nothing measured runs beside them.
void press_other_tools(CaseRun& run, BuiltVariant& built, const std::vector<double>& path) {
  const int n = static_cast<int>(run.other_tools.size());
  if (n == 0) return;
  const Problem& problem = run.problem;
  std::vector<ToolLoadVariant> results(n);
  std::vector<std::exception_ptr> errors(n);
  auto work = [&](BuiltVariant& variant, int first) {
    for (int k = first; k < n; k += 2) {
      try {
        const ToolLoad& load = run.other_tools[k];
        const ToolPlacement& other = problem.tools[load.tool];
        std::vector<ForceDepthPoint> curve;
        const StaticSolution at = press(variant, other, path, curve);
        results[k] = compare_at_tool(problem, variant, at, std::move(curve), load.fem,
                                     load.compared_vertices, other);
      } catch (...) {
        errors[k] = std::current_exception();
      }
    }
  };
  if (n == 1 || std::thread::hardware_concurrency() < 2) {
    work(built, 0);
  } else {
    const std::optional<ToolPlacement> first_tool = problem.tools.front();
    BuiltVariant copy = build_variant(built.kind, problem, run.mesh, first_tool);
    std::thread second([&] { work(copy, 1); });
    work(built, 0);
    second.join();
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
  for (int k = 0; k < n; ++k)
    run.other_tools[k].variants.push_back(std::move(results[k]));
}

// Solves (or reads from the cache) the FEM at every load of the run, its force-depth curve and its
// own error estimate, and fills in each load's compared vertices.
void reference_solutions(CaseRun& run, const RunSettings& settings,
                         const std::vector<double>& depths, int other_tools,
                         const Progress& progress) {
  const Problem& problem = run.problem;
  const std::optional<ToolPlacement> tool =
      problem.tools.empty() ? std::nullopt : std::optional<ToolPlacement>(problem.tools.front());
  run.fem_cache_key = fem_cache_key(problem, depths, other_tools > 0);
  std::optional<FemCacheEntry> cached;
  if (settings.fem_cache_directory)
    cached = load_fem_cache(*settings.fem_cache_directory, run.fem_cache_key);
  if (cached && static_cast<int>(cached->other_tools.size()) != other_tools) cached.reset();
  std::vector<FemSolution> other_fem;
  if (cached) {
    progress.stage("FEM reference from the cache (" +
                   (*settings.fem_cache_directory / (run.fem_cache_key + ".cbor")).string() +
                   "): nothing it depends on changed");
    run.mesh = std::move(cached->mesh);
    run.fem = std::move(cached->solution);
    run.fem_force_depth = std::move(cached->force_depth);
    other_fem = std::move(cached->other_tools);
    run.fem_error = std::move(cached->error_estimate);
    run.fem_from_cache = true;
  } else {
    progress.stage("meshing the volume (Gmsh) for the FEM reference");
    // One mesh for every load, refined at each tool it presses with.
    run.mesh = other_tools > 0 ? mesh_problem(problem, problem.tools) : mesh_problem(problem);
    // Decided (and refused, for a method that cannot run) before the first solve.
    const ErrorEstimatePlan plan =
        plan_error_estimate(problem, run.mesh, reference_solve_count(problem), 1 + other_tools);
    check_no_rigid_motion(problem, run.mesh, tool);
    progress.stage("solving the FEM reference (P" + std::to_string(problem.parameters.fem.degree) +
                   ", " + std::to_string(run.mesh.num_tetrahedra()) + " tetrahedra)");
    run.fem = solve_fem(problem, run.mesh, tool);
    run.fem_force_depth = fem_force_depth(problem, run.mesh, run.fem, tool, depths, progress);
    const auto others_start = Clock::now();
    for (int t = 1; t <= other_tools; ++t) {
      other_fem.push_back(solve_fem(problem, run.mesh, problem.tools[t]));
      progress.advance("FEM at the other tool positions", t, other_tools,
                       seconds_since(others_start));
    }
    if (plan.method != cases::FemParameters::ErrorEstimate::none)
      progress.stage("estimating the reference's own error (" + plan.note + ")");
    run.fem_error = estimate_run_error(problem, run.mesh, plan, run.fem, other_fem);
    if (settings.fem_cache_directory)
      store_fem_cache(*settings.fem_cache_directory, run.fem_cache_key,
                      {run.mesh, run.fem, run.fem_force_depth, other_fem, run.fem_error});
  }
  if (run.mesh.num_tetrahedra() > 0)
    run.worst_cell_quality = fem_reference::cell_quality(run.mesh).minCoeff();
  for (int t = 1; t <= other_tools; ++t) {
    ToolLoad load;
    load.tool = t;
    load.fem = std::move(other_fem[t - 1]);
    load.compared_vertices = unprescribed_vertices(problem, problem.tools[t]);
    run.other_tools.push_back(std::move(load));
  }
}

// One variant on the run's problem: pressed along the loading path at every tool, compared with
// the FEM, timed, with its warnings.
VariantResult run_variant(CaseRun& run, BuiltVariant& built, const std::vector<double>& path,
                          const RunSettings& settings) {
  const Problem& problem = run.problem;
  const std::optional<ToolPlacement> tool =
      problem.tools.empty() ? std::nullopt : std::optional<ToolPlacement>(problem.tools.front());
  VariantResult r;
  r.nodes = built.model->num_nodes();
  r.springs = built.model->network().num_springs();
  r.refinement_added_nodes = built.refinement_added_nodes;
  r.warnings = built.warnings;
  r.parameters = variant_parameters(*built.model);
  std::vector<ForceDepthPoint> curve;
  const StaticSolution s = press(built, tool, path, curve);
  static_cast<ToolLoadVariant&>(r) =
      compare_at_tool(problem, built, s, std::move(curve), run.fem, run.compared_vertices, tool);
  if (tool)
    if (auto warning = buckling_warning(r.force_depth, *tool, run.fem, built.tetrahedra.rows()))
      r.warnings.push_back(*warning);
  std::string unresolved;
  for (const std::string& metric : unresolved_metrics(run, r))
    unresolved += (unresolved.empty() ? "" : ", ") + metric;
  if (!unresolved.empty())
    r.warnings.push_back("not resolved by this reference: " + unresolved +
                         " within 3x of the FEM's own estimated error (a finer fem/cell "
                         "size resolves it)");
  r.newton_iterations = s.newton_iterations;
  r.equilibrium = s.x;
  r.surface_displacement = s.surface_displacement;
  r.error = s.surface_displacement - run.fem.surface_displacement;
  if (settings.time_dynamics) r.timing = time_variant(built, problem.parameters.timing, s.x);
  press_other_tools(run, built, path);
  for (const ToolLoad& load : run.other_tools)
    if (auto warning = buckling_warning(load.variants.back().force_depth, problem.tools[load.tool],
                                        load.fem, built.tetrahedra.rows()))
      r.warnings.push_back("at tool " + std::to_string(load.tool) + ": " + *warning);
  return r;
}

}  // namespace

void Progress::stage(const std::string& what) const {
  if (!quiet_) std::fprintf(stderr, "msfem: %s\n", what.c_str());
}

void Progress::advance(const std::string& what, int done, int total, double elapsed_s) const {
  if (quiet_) return;
  const double left = done > 0 ? elapsed_s / done * (total - done) : 0.0;
  std::fprintf(stderr, "msfem: %s %d/%d (%.0f %%, %.1f s, about %.0f s left)\n", what.c_str(), done,
               total, 100.0 * done / total, elapsed_s, left);
}

std::vector<double> curve_depths(const cases::ToolParameters& tool) {
  if (!tool.curve_depths_m.empty()) return tool.curve_depths_m;
  return {0.25 * tool.depth_m, 0.5 * tool.depth_m, 0.75 * tool.depth_m, tool.depth_m};
}

std::vector<double> loading_path(std::vector<double> depths, double case_depth, double step) {
  depths.push_back(case_depth);
  std::sort(depths.begin(), depths.end());
  depths.erase(std::unique(depths.begin(), depths.end()), depths.end());
  if (!(step > 0)) return depths;
  std::vector<double> path;
  double last = 0.0;
  for (double d : depths) {
    // Equal increments no longer than `step`; the recorded depth itself stays exact.
    const int pieces = static_cast<int>(std::ceil((d - last) / step - 1e-9));
    for (int i = 1; i < pieces; ++i)
      path.push_back(last + (d - last) * i / pieces);
    path.push_back(d);
    last = d;
  }
  return path;
}

std::optional<double> force_depth_exponent(const std::vector<ForceDepthPoint>& curve,
                                           const std::optional<ToolPlacement>& tool) {
  if (!tool || curve.size() < 2) return std::nullopt;
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const ForceDepthPoint& p : curve) {
    const double push = p.force_n.dot(tool->outward_normal);
    if (!(push > 0.0) || !(p.depth_m > 0.0)) return std::nullopt;
    const double x = std::log(p.depth_m), y = std::log(push);
    n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  const double spread = n * sxx - sx * sx;
  if (!(spread > 0.0)) return std::nullopt;
  return (n * sxy - sx * sy) / spread;
}

BucklingOnset buckling_onset(std::vector<ForceDepthPoint> curve, const ToolPlacement& tool,
                             double max_lateral_fraction) {
  std::sort(curve.begin(), curve.end(),
            [](const auto& a, const auto& b) { return a.depth_m < b.depth_m; });
  BucklingOnset onset;
  for (std::size_t i = 0; i < curve.size(); ++i) {
    const Eigen::Vector3d& f = curve[i].force_n;
    if (i > 0 && !onset.force_falls_at_m &&
        !(f.dot(tool.outward_normal) > curve[i - 1].force_n.dot(tool.outward_normal)))
      onset.force_falls_at_m = curve[i].depth_m;
    const double fraction = lateral_fraction(f, tool.outward_normal);
    if (!onset.turns_sideways_at_m && fraction > max_lateral_fraction) {
      onset.turns_sideways_at_m = curve[i].depth_m;
      onset.lateral_fraction = fraction;
    }
  }
  return onset;
}

std::optional<bool> force_grows_with_depth(std::vector<ForceDepthPoint> curve,
                                           const std::optional<ToolPlacement>& tool) {
  if (!tool || curve.size() < 2) return std::nullopt;
  std::sort(curve.begin(), curve.end(),
            [](const auto& a, const auto& b) { return a.depth_m < b.depth_m; });
  for (std::size_t i = 1; i < curve.size(); ++i)
    if (!(curve[i].force_n.dot(tool->outward_normal) >
          curve[i - 1].force_n.dot(tool->outward_normal)))
      return false;
  return true;
}

CaseRun run_case(const cases::CaseParameters& parameters, const RunSettings& settings) {
  const auto start = Clock::now();
  const Progress progress(settings.quiet);
  check_group_names(parameters);
  CaseRun run;
  progress.stage("loading the surface and placing supports and loads");
  run.problem = make_problem(parameters);
  const Problem& problem = run.problem;
  check_variants_fit(problem);
  const std::optional<ToolPlacement> tool =
      problem.tools.empty() ? std::nullopt : std::optional<ToolPlacement>(problem.tools.front());

  std::vector<double> depths;
  if (tool && settings.force_depth_curve) depths = curve_depths(parameters.loads.tool);
  const int other_tools =
      settings.all_tools ? std::max(0, static_cast<int>(problem.tools.size()) - 1) : 0;
  reference_solutions(run, settings, depths, other_tools, progress);

  run.fem_force_depth_monotone = force_grows_with_depth(run.fem_force_depth, tool);

  run.compared_vertices = unprescribed_vertices(problem, tool);

  // One loading path whatever a command writes: --no-curve skips the FEM's curve and the curves'
  // output, never the path the variants are pressed along (their equilibria would differ).
  const std::vector<double> path =
      tool ? loading_path(curve_depths(parameters.loads.tool), tool->depth,
                          parameters.loads.tool.path_step_m)
           : std::vector<double>{};
  const auto variants_start = Clock::now();
  const int total = static_cast<int>(parameters.mass_spring.variants.size());
  for (int i = 0; i < total; ++i) {
    const cases::Variant kind = parameters.mass_spring.variants[i];
    const std::string name = cases::name_of(kind);
    BuiltVariant built = build_variant(kind, problem, run.mesh, tool);
    try {
      VariantResult r = run_variant(run, built, path, settings);
      run.variants.push_back(std::move(r));
    } catch (const cases::InputError&) {
      throw;
    } catch (const std::runtime_error& e) {
      // One variant's Newton or time stepping failing must not cost the others' results.
      run.failed_variants.emplace_back(name, e.what());
      progress.stage("variant " + name + " failed: " + e.what());
    }
    progress.advance("variant " + name, i + 1, total, seconds_since(variants_start));
  }
  if (!settings.force_depth_curve) {
    for (auto& v : run.variants)
      v.force_depth.clear();
    for (auto& load : run.other_tools)
      for (auto& v : load.variants)
        v.force_depth.clear();
  }
  if (run.variants.empty() && !run.failed_variants.empty()) {
    std::string all;
    for (const auto& [name, why] : run.failed_variants)
      all += (all.empty() ? "" : "; ") + name + ": " + why;
    // A time step no variant can take is the case's error (exit 2), named by its key.
    if (parameters.timing.dt_s > 0 && settings.time_dynamics)
      throw cases::InputError(parameters.file.string() +
                              ": timing/dt = " + std::to_string(parameters.timing.dt_s) +
                              " s: every variant failed with it (0 takes half each variant's "
                              "stable step): " +
                              all);
    throw std::runtime_error("every variant failed: " + all);
  }
  run.wall_time_s = seconds_since(start);
  return run;
}

std::vector<std::string> unresolved_metrics(const CaseRun& run, const ToolLoadVariant& variant,
                                            int load) {
  std::vector<std::string> metrics;
  if (load >= static_cast<int>(run.fem_error.loads.size())) return metrics;
  const LoadErrorEstimate& estimate = run.fem_error.loads[static_cast<std::size_t>(load)];
  if (within_reference_error(variant.errors.all.rel_l2_error, estimate.rel_l2_error))
    metrics.emplace_back("rel_l2_error");
  if (!run.problem.tools.empty() &&
      within_reference_error(variant.reaction_force_rel_error, estimate.force_rel_error))
    metrics.emplace_back("reaction_force_rel_error");
  if (variant.patch_displacement_rel_error &&
      within_reference_error(*variant.patch_displacement_rel_error, estimate.force_rel_error))
    metrics.emplace_back("patch_displacement_rel_error");
  return metrics;
}

std::vector<ToolLoadVariant> per_tool(const CaseRun& run, const VariantResult& v) {
  std::vector<ToolLoadVariant> list = {static_cast<const ToolLoadVariant&>(v)};
  for (const auto& load : run.other_tools)
    for (const auto& o : load.variants)
      if (o.name == v.name) list.push_back(o);
  return list;
}

}  // namespace msfem::compare
