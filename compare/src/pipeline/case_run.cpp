#include "msfem/compare/pipeline/case_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <thread>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/compare/pipeline/external_result.hpp"
#include "msfem/compare/pipeline/fem_cache.hpp"
#include "msfem/compare/pipeline/ranks.hpp"
#include "msfem/fem_reference/volume_mesh.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "variant_share.hpp"

namespace msfem::compare {
namespace {

VariantParameters variant_parameters(const massspring::MassSpringModel& model) {
  const auto& n = model.network();
  VariantParameters parameters;
  for (std::size_t g = 0; g < n.spring_group_names.size(); ++g) {
    double k = 0, d = 0;
    int count = 0;
    for (int i = 0; i < n.num_springs(); ++i)
      if (n.spring_group[i] == static_cast<int>(g)) {
        k += n.stiffness[i];
        d += n.damping[i];
        ++count;
      }
    parameters.spring_groups[n.spring_group_names[g]] = {count, count ? k / count : 0.0,
                                                         count ? d / count : 0.0};
  }
  parameters.total_mass_kg = n.masses.sum();
  parameters.anchors = n.num_anchors();
  parameters.constrained_nodes = static_cast<int>(model.constrained_nodes().size());
  if (const auto& volume = model.volume())
    parameters.volume_preservation = VariantParameters::Volume{volume->elements().num_elements(),
                                                               volume->elements().modulus.mean()};
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
  std::string why = "buckles under the tool:";
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

// The FEM at every load of the run (each tool position of the case, or the one load without a
// tool), on one mesh refined at each tool it presses with.
void reference_at_every_load(CaseRun& run, const RunSettings& settings, const Progress& progress) {
  const Problem& problem = run.problem;
  ReferenceRequest request;
  request.loads = {problem.tools.empty() ? std::nullopt
                                         : std::optional<ToolPlacement>(problem.tools.front())};
  if (settings.all_tools)
    for (std::size_t t = 1; t < problem.tools.size(); ++t)
      request.loads.emplace_back(problem.tools[t]);
  for (const auto& t : request.loads)
    if (t) request.refine_near.push_back(*t);
  const std::optional<ToolPlacement>& tool = request.loads.front();
  if (tool && settings.force_depth_curve)
    request.curve_depths = curve_depths(problem.parameters.loads.tool);
  request.planned_solves = reference_solve_count(problem);
  request.cache_directory = settings.fem_cache_directory;
  FemReferences references = fem_references(problem, request, progress);
  run.mesh = std::move(references.mesh);
  run.loads = std::move(references.loads);
  run.fem_error = std::move(references.estimate);
  run.worst_cell_quality = references.worst_cell_quality;
  run.fem_from_cache = references.solved == 0;
  run.fem_force_depth_monotone = force_grows_with_depth(run.loads.front().force_depth, tool);
}

// A variant that ends with no force on the tool where the FEM pushes back has lost it: its surface
// gave way, or slid off the sphere.
bool lost_the_tool(const Eigen::Vector3d& force, const Eigen::Vector3d& fem_force,
                   const ToolPlacement& tool) {
  return fem_force.dot(tool.outward_normal) > 0 && force.norm() <= 1e-9 * fem_force.norm();
}

// The variant's equilibrium `s` (reached along `curve`) against the FEM's at the same load.
ToolLoadVariant compare_at_load(const Problem& problem, const BuiltVariant& built,
                                const StaticSolution& s, std::vector<ForceDepthPoint> curve,
                                const LoadReference& load) {
  ToolLoadVariant o = measure_at_load(problem, built.name, s.surface_displacement, s.tool_force,
                                      std::move(curve), load);
  o.inverted_elements = inverted_tetrahedra(built, s.x);
  o.newton_iterations = s.newton_iterations;
  o.equilibrium = s.x;
  return o;
}

}  // namespace

namespace detail {

ToolLoadVariant at_load(const Problem& problem, BuiltVariant& built, const LoadReference& load,
                        const std::vector<double>& path) {
  std::vector<ForceDepthPoint> curve;
  const StaticSolution s = press(built, load.tool, path, &curve);
  return compare_at_load(problem, built, s, std::move(curve), load);
}

void warn_at_load(const CaseRun& run, long long tetrahedra, std::size_t load, VariantResult& r) {
  const LoadReference& reference = run.loads[load];
  const ToolLoadVariant& result = r.loads[load];
  if (reference.tool)
    if (auto warning =
            buckling_warning(result.force_depth, *reference.tool, reference.fem, tetrahedra))
      r.warnings.push_back({Warning::Kind::buckling, std::move(*warning), load});
  if (reference.tool && result.lost_tool) {
    char text[320];
    std::snprintf(
        text, sizeof text,
        "loses the tool: at %.3g mm it pushes back with %.3g N where the FEM does with %.3g N (its "
        "surface gave way or slid off the sphere): its force is no answer",
        1e3 * reference.tool->depth, result.tool_force.norm(), reference.fem.tool_force.norm());
    r.warnings.push_back({Warning::Kind::lost_tool, text, load});
  }
  if (load != 0) return;
  const std::vector<Metric> metrics = unresolved_metrics(run, result, load);
  if (metrics.empty()) return;
  std::string unresolved;
  for (const Metric metric : metrics)
    unresolved += (unresolved.empty() ? "" : ", ") + std::string(metric_name(metric));
  r.warnings.push_back({Warning::Kind::unresolved_metrics,
                        "not resolved by this reference: " + unresolved +
                            " within 3x of the FEM's own estimated error (a finer fem/cell "
                            "size resolves it)",
                        load, metrics});
}

VariantResult variant_header(const BuiltVariant& built) {
  VariantResult r;
  r.spec = built.spec;
  r.name = built.name;
  r.nodes = built.model->num_nodes();
  r.springs = built.model->network().num_springs();
  r.refinement_added_nodes = built.refinement_added_nodes;
  r.warnings = built.warnings;
  r.parameters = variant_parameters(*built.model);
  r.parameters.youngs_modulus_min_pa = built.youngs_modulus_range.min;
  r.parameters.youngs_modulus_max_pa = built.youngs_modulus_range.max;
  return r;
}

}  // namespace detail

namespace {

using detail::at_load;

// The variant at loads [first, end) of the run. Two workers (each with its own copy of the
// network) share them: the statics are independent and a machine with two cores finishes the
// brain's tools in about half the time. Nothing timed runs beside them.
void press_loads(const CaseRun& run, BuiltVariant& built, const std::vector<double>& path,
                 std::size_t first, std::vector<ToolLoadVariant>& results) {
  const std::size_t n = run.loads.size();
  if (first >= n) return;
  results.resize(n);
  std::vector<std::exception_ptr> errors(n);
  auto work = [&](BuiltVariant& variant, std::size_t from, std::size_t stride) {
    for (std::size_t k = from; k < n; k += stride) {
      try {
        results[k] = at_load(run.problem, variant, run.loads[k], path);
      } catch (...) {
        errors[k] = std::current_exception();
      }
    }
  };
  if (n - first == 1 || std::thread::hardware_concurrency() < 2) {
    work(built, first, 1);
  } else {
    BuiltVariant copy = build_variant(built.spec, run.problem, run.mesh, run.loads.front().tool);
    std::thread second([&] { work(copy, first + 1, 2); });
    work(built, first, 2);
    second.join();
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

// One variant on the run's problem: pressed along the loading path at every load, compared with
// the FEM, timed from its equilibrium at the first, with its warnings.
VariantResult run_variant(const CaseRun& run, BuiltVariant& built, const std::vector<double>& path,
                          const RunSettings& settings) {
  VariantResult r = detail::variant_header(built);
  // The first load on the variant itself: the timing starts from its equilibrium, pressed there.
  r.loads.push_back(at_load(run.problem, built, run.loads.front(), path));
  if (settings.time_dynamics)
    r.timing = time_variant(built, run.problem.parameters.timing, r.loads.front().equilibrium);
  press_loads(run, built, path, 1, r.loads);
  for (std::size_t load = 0; load < r.loads.size(); ++load)
    detail::warn_at_load(run, built.tetrahedra.rows(), load, r);
  return r;
}

// Every variant of the case on this process, one after another.
void run_variants(CaseRun& run, const std::vector<double>& path, const RunSettings& settings,
                  const Progress& progress) {
  const auto start = Clock::now();
  const std::vector<VariantSpec> variants = variant_specs(run.problem.parameters);
  const int total = static_cast<int>(variants.size());
  for (int i = 0; i < total; ++i) {
    const std::string& name = variants[i].name;
    BuiltVariant built = build_variant(variants[i], run.problem, run.mesh, run.loads.front().tool);
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
    progress.advance("variant " + name, i + 1, total, seconds_since(start));
  }
}

}  // namespace

LoadErrors load_errors(const Problem& problem, const LoadReference& reference,
                       const Eigen::MatrixX3d& surface_displacement,
                       const std::optional<Eigen::Vector3d>& tool_force) {
  const FemSolution& fem = reference.fem;
  const std::optional<ToolPlacement>& tool = reference.tool;
  const Eigen::Index n = fem.surface_displacement.rows();
  if (surface_displacement.rows() < n)
    throw std::invalid_argument(
        "displacement fields differ in size: " + std::to_string(surface_displacement.rows()) +
        " vs " + std::to_string(n) + " vertices");
  LoadErrors e;
  e.displacement = zoned_displacement_error(
      surface_displacement.topRows(n), fem.surface_displacement, problem.surface.vertices,
      reference.compared_vertices, tool ? tool->contact_point : problem.centroid,
      tool ? 2 * tool->radius : 0.0);
  e.force_measured = tool_force.has_value();
  if (tool_force) e.tool_force = *tool_force;
  if (tool && tool_force)
    e.reaction_force_rel_error = reaction_force_rel_error(*tool_force, fem.tool_force);
  return e;
}

ToolLoadVariant measure_at_load(const Problem& problem, const std::string& name,
                                const Eigen::MatrixX3d& surface_displacement,
                                const std::optional<Eigen::Vector3d>& tool_force,
                                std::vector<ForceDepthPoint> curve, const LoadReference& load) {
  const FemSolution& fem = load.fem;
  const std::optional<ToolPlacement>& tool = load.tool;
  // The answer's surface is the case's (a variant's finer surface is cut to it when solved).
  if (surface_displacement.rows() != fem.surface_displacement.rows())
    throw std::invalid_argument(
        "displacement fields differ in size: " + std::to_string(surface_displacement.rows()) +
        " vs " + std::to_string(fem.surface_displacement.rows()) + " vertices");
  ToolLoadVariant o;
  static_cast<LoadErrors&>(o) = load_errors(problem, load, surface_displacement, tool_force);
  o.name = name;
  if (tool && tool_force) o.lost_tool = lost_the_tool(*tool_force, fem.tool_force, *tool);
  o.volume_change = volume_change(problem.surface, surface_displacement);
  o.force_depth_monotone = force_grows_with_depth(curve, tool);
  o.force_depth = std::move(curve);
  const std::vector<int> patch = patch_vertices(problem);
  if (!patch.empty()) {
    const Eigen::Vector3d reference = mean_displacement(fem.surface_displacement, patch);
    o.patch_mean_displacement = mean_displacement(surface_displacement, patch);
    o.patch_displacement_rel_error =
        (*o.patch_mean_displacement - reference).norm() / reference.norm();
  }
  o.surface_displacement = surface_displacement;
  o.error = surface_displacement - fem.surface_displacement;
  return o;
}

StaticSolution press(BuiltVariant& built, const std::optional<ToolPlacement>& tool,
                     const std::vector<double>& path, std::vector<ForceDepthPoint>* curve) {
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
    if (curve) curve->push_back({depth, at.tool_force, inverted_tetrahedra(built, at.x), {}});
    if (depth == tool->depth) s = std::move(at);
  }
  set_tool_depth(built, *tool);
  return s;
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

double path_step_of(const cases::ToolParameters& tool) {
  const double step = tool.path_step_m;
  if (tool.mode != cases::ToolParameters::Mode::contact) return step;
  const double limit = 0.25 * tool.radius_m;
  return step > 0 ? std::min(step, limit) : limit;
}

std::vector<double> loading_path(const cases::ToolParameters& tool, double depth) {
  std::vector<double> depths = {0.25 * depth, 0.5 * depth, 0.75 * depth, depth};
  if (!tool.curve_depths_m.empty()) {
    depths = tool.curve_depths_m;
    // The case's own depth maps onto the load's exactly, so that the load's equilibrium is one
    // point of the path, not two an ulp apart.
    for (double& d : depths)
      d = d == tool.depth_m ? depth : d * (depth / tool.depth_m);
  }
  return loading_path(std::move(depths), depth, path_step_of(tool));
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
  check_variants_fit(run.problem);
  check_results_fit(run.problem);
  reference_at_every_load(run, settings, progress);
  const std::optional<ToolPlacement>& tool = run.loads.front().tool;

  // One loading path whatever a command writes: --no-curve skips the FEM's curve and the curves'
  // output, never the path the variants are pressed along (their equilibria would differ).
  const std::vector<double> path =
      tool ? loading_path(parameters.loads.tool, tool->depth) : std::vector<double>{};
  if (ranks::count() > 1)
    detail::run_variants_across_ranks(run, path, settings, progress);
  else
    run_variants(run, path, settings, progress);
  for (VariantResult& v : external_variants(run))
    run.variants.push_back(std::move(v));
  if (!settings.force_depth_curve)
    for (auto& v : run.variants)
      for (auto& load : v.loads)
        load.force_depth.clear();
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

std::vector<Metric> unresolved_metrics(const CaseRun& run, const ToolLoadVariant& variant,
                                       std::size_t load) {
  std::vector<Metric> metrics;
  if (load >= run.loads.size()) return metrics;
  const LoadErrorEstimate& estimate = run.loads[load].fem_error;
  if (within_reference_error(variant.displacement.all.rel_l2_error, estimate.rel_l2_error))
    metrics.push_back(Metric::rel_l2_error);
  if (run.loads[load].tool &&
      within_reference_error(variant.reaction_force_rel_error, estimate.force_rel_error))
    metrics.push_back(Metric::reaction_force_rel_error);
  if (variant.patch_displacement_rel_error &&
      within_reference_error(*variant.patch_displacement_rel_error, estimate.force_rel_error))
    metrics.push_back(Metric::patch_displacement_rel_error);
  return metrics;
}

}  // namespace msfem::compare
