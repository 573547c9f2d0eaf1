#include "msfem/compare/calibration/calibration_case.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/network_file.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/cases/surface_from_image.hpp"
#include "msfem/cases/surface_generators.hpp"
#include "msfem/compare/pipeline/case_run.hpp"
#include "msfem/compare/pipeline/fem_references.hpp"
#include "msfem/compare/pipeline/fem_run.hpp"
#include "msfem/fem_reference/volume_mesh.hpp"
#include "msfem/massspring/mass_spring_model.hpp"

namespace msfem::compare {
namespace {

// The variant to fit: --variant, else calibration/variant, else the case's first (a built-in
// one, else a network); it must be one the case runs.
VariantSpec resolve_variant(const cases::CaseParameters& p, const CalibrationRequest& request) {
  const std::vector<VariantSpec> defined = variant_specs(p);
  if (defined.empty())
    throw cases::InputError(p.file.string() +
                            ": msfem calibrate: the case has no variant (mass spring/variants and "
                            "mass spring/networks are empty)");
  const std::optional<std::string> asked =
      request.variant ? request.variant : p.calibration.variant;
  if (!asked) return defined.front();
  for (const VariantSpec& spec : defined)
    if (spec.name == *asked) return spec;
  std::string list;
  for (const auto& v : defined)
    list += (list.empty() ? "" : ", ") + v.name;
  throw cases::InputError(p.file.string() + ": " +
                          (request.variant ? "--variant " : "calibration/variant = ") + *asked +
                          ": the case does not run it (its variants and networks: " + list + ")");
}

void check_loads(const cases::CaseParameters& p, const std::vector<cases::ToolLoad>& train,
                 const std::vector<cases::ToolLoad>& test) {
  const std::string file = p.file.string();
  if (train.empty())
    throw cases::InputError(file +
                            ": calibration: the training set is empty (give --train or set "
                            "calibration/train loads)");
  for (const auto& a : test)
    for (const auto& b : train)
      if (a.same_as(b))
        throw cases::InputError(file + ": calibration: load " + a.label() +
                                " is both a training and a held-out load (held-out loads must "
                                "differ from the training ones)");
  auto check_unique = [&](const std::vector<cases::ToolLoad>& loads, const char* what) {
    for (std::size_t i = 0; i < loads.size(); ++i)
      for (std::size_t j = i + 1; j < loads.size(); ++j)
        if (loads[i].same_as(loads[j]))
          throw cases::InputError(file + ": calibration: load " + loads[i].label() +
                                  " appears twice in the " + what + " set");
  };
  check_unique(train, "training");
  check_unique(test, "held-out");
}

// Before any solve: every group to fit is one the variant has. A network hands its fit back as
// its own file with new spring coefficients, so its groups to fit are its spring groups (every one
// when none is named); the modulus of its volume elements stays the file's.
std::vector<std::string> checked_fit_groups(const cases::CaseParameters& p,
                                            const VariantSpec& variant,
                                            std::vector<std::string> groups) {
  std::vector<std::string> known;
  if (variant.builtin) {
    known = spring_groups_of(*variant.builtin, p);
  } else {
    try {
      known = network_groups(variant.network);
    } catch (const cases::InputError& e) {
      throw cases::InputError(p.file.string() + ": mass spring/networks: " + variant.name + "=" +
                              variant.network.string() + ": " + e.what());
    }
    known.erase(std::remove(known.begin(), known.end(), volume_group), known.end());
    if (groups.empty()) groups = known;
  }
  for (const auto& g : groups)
    if (std::find(known.begin(), known.end(), g) == known.end()) {
      std::string list;
      for (const auto& k : known)
        list += (list.empty() ? "" : ", ") + k;
      const std::string hint =
          g != volume_group ? ""
          : variant.builtin ? "; " + std::string(volume_hint)
                            : "; a network's fit is handed back as new spring coefficients in "
                              "its file, and its volume elements keep the file's bulk_modulus";
      throw cases::InputError(p.file.string() + ": calibration: variant " + variant.name +
                              " has no group '" + g + "' to fit (its groups: " + list + hint + ")");
    }
  return groups;
}

// The case with its tool enabled at every direction the loads use, as deep as the deepest load
// (make_problem checks that depth against the model's size).
Problem calibration_problem(cases::CaseParameters p, const std::vector<cases::ToolLoad>& loads) {
  auto& tool = p.loads.tool;
  tool.enabled = true;
  tool.directions.clear();
  tool.depth_m = 0.0;
  for (const auto& l : loads) {
    tool.depth_m = std::max(tool.depth_m, l.depth_m);
    if (std::none_of(tool.directions.begin(), tool.directions.end(),
                     [&](const Eigen::Vector3d& d) { return (d - l.direction).norm() < 1e-9; }))
      tool.directions.push_back(l.direction);
  }
  return make_problem(p);
}

ToolPlacement placement_of(const Problem& problem, const cases::ToolLoad& load) {
  const auto& directions = problem.parameters.loads.tool.directions;
  for (std::size_t i = 0; i < directions.size(); ++i)
    if ((directions[i] - load.direction).norm() < 1e-9)
      return at_depth(problem.tools[i], load.depth_m);
  throw std::logic_error("calibration: no tool placed for load " + load.label());
}

// Two directions can pick the same surface vertex: a held-out load pressed where and as deep as a
// training load is the same load, and would check the fit on what it was fitted to.
void check_distinct_vertices(const Problem& problem, const std::vector<cases::ToolLoad>& train,
                             const std::vector<cases::ToolLoad>& test) {
  for (const auto& a : test)
    for (const auto& b : train) {
      const ToolPlacement pa = placement_of(problem, a), pb = placement_of(problem, b);
      if (pa.vertex == pb.vertex && std::abs(a.depth_m - b.depth_m) < 1e-12)
        throw cases::InputError(problem.parameters.file.string() + ": calibration: held-out load " +
                                a.label() + " presses the same surface vertex (" +
                                std::to_string(pa.vertex) + ") as deep as training load " +
                                b.label() + ": it is the same load");
    }
}

// The FEM of every load through the pipeline's one cache, on one mesh refined at every tool.
void solve_references(CaseCalibration& c, const std::vector<cases::ToolLoad>& train,
                      const std::vector<cases::ToolLoad>& test, const CalibrationRequest& request,
                      const Progress& progress) {
  const Problem& problem = c.problem;
  std::vector<cases::ToolLoad> all = train;
  all.insert(all.end(), test.begin(), test.end());
  ReferenceRequest r;
  for (const auto& load : all)
    r.loads.emplace_back(placement_of(problem, load));
  r.refine_near = problem.tools;
  r.planned_solves = static_cast<int>(all.size());
  r.cache_directory = request.fem_cache_directory;
  const auto start = Clock::now();
  FemReferences references = fem_references(problem, r, progress);
  c.mesh = std::move(references.mesh);
  c.fem_solves = references.solved;
  c.fem_from_cache = references.from_cache;
  for (std::size_t i = 0; i < all.size(); ++i) {
    LoadReference& fem = references.loads[i];
    CalibrationLoad load;
    static_cast<LoadReference&>(load) = std::move(fem);
    load.load = all[i];
    (i < train.size() ? c.train : c.test).push_back(std::move(load));
  }
  c.fem_time_s = seconds_since(start);
}

// Fitted errors within 3x of the reference's own at their load: the fit cannot be judged there.
void note_unresolved_loads(CaseCalibration& c) {
  std::string list;
  auto check = [&](const std::vector<CalibrationLoad>& references,
                   const std::vector<CalibrationErrors>& errors) {
    for (std::size_t i = 0; i < references.size() && i < errors.size(); ++i) {
      const LoadErrorEstimate& e = references[i].fem_error;
      if (within_reference_error(errors[i].displacement.all.rel_l2_error, e.rel_l2_error) ||
          within_reference_error(errors[i].reaction_force_rel_error, e.force_rel_error))
        list += (list.empty() ? "" : ", ") + references[i].load.label();
    }
  };
  check(c.train, c.fit.after.train);
  check(c.test, c.fit.after.test);
  if (!list.empty())
    c.notes.push_back("not resolved by this reference: after the fit, the error at " + list +
                      " is within 3x of the FEM's own estimated error (fem.error_estimate); a "
                      "finer fem/cell size is needed to judge the fit there");
}

// Group scales of the calibrated case: the case's own entries with the fitted groups replaced.
std::vector<std::pair<std::string, double>> calibrated_group_scales(
    const cases::CaseParameters& p, const std::vector<FittedGroup>& fitted) {
  std::vector<std::pair<std::string, double>> scales;
  for (const auto& [group, factor] : p.mass_spring.group_scales)
    if (std::none_of(fitted.begin(), fitted.end(),
                     [&](const FittedGroup& f) { return f.group == group; }))
      scales.emplace_back(group, factor);
  for (const auto& f : fitted)
    scales.emplace_back(f.group, f.case_factor);
  return scales;
}

std::string group_scales_assignment(const std::vector<std::pair<std::string, double>>& scales) {
  std::string text = "mass spring/group scales=";
  char buffer[64];
  for (std::size_t i = 0; i < scales.size(); ++i) {
    std::snprintf(buffer, sizeof buffer, "%.10g", scales[i].second);
    text += (i ? ", " : "") + scales[i].first + ":" + buffer;
  }
  return text;
}

VariantOnTest mean_on(const std::string& name, bool calibrated,
                      const std::vector<CalibrationErrors>& errors) {
  VariantOnTest v{name, calibrated, 0.0, 0.0};
  for (const auto& e : errors) {
    v.mean_rel_l2_error += e.displacement.all.rel_l2_error / errors.size();
    v.mean_reaction_force_rel_error += e.reaction_force_rel_error / errors.size();
  }
  return v;
}

// Below this many tool nodes the report warns (see CalibrationErrors::tool_patch_nodes).
constexpr int min_tool_patch_nodes = 3;

// "load (N nodes), ..." for every training or held-out load whose tool patch is that small.
std::string loads_with_few_tool_nodes(const ErrorsOnLoads& errors) {
  std::string list;
  for (const auto* set : {&errors.train, &errors.test})
    for (const CalibrationErrors& e : *set)
      if (e.tool_patch_nodes < min_tool_patch_nodes)
        list += (list.empty() ? "" : ", ") + e.load + " (" + std::to_string(e.tool_patch_nodes) +
                (e.tool_patch_nodes == 1 ? " node)" : " nodes)");
  return list;
}

// The fit's settings from the case and the request, checked before anything is solved.
void set_options(CaseCalibration& c, const cases::CaseParameters& parameters,
                 const CalibrationRequest& request) {
  const auto& defaults = parameters.calibration;
  // The linearised statics hold the tool as a prescribed patch; a frictionless tool would be
  // fitted against loads it does not apply. The nonlinear fit presses by contact as msfem run does.
  if (parameters.loads.tool.mode == cases::ToolParameters::Mode::contact &&
      defaults.model == cases::CalibrationModel::linear)
    throw cases::InputError(parameters.file.string() +
                            ": calibration/model = linear holds the tool as a bonded patch, but "
                            "loads/tool/mode = contact: use calibration/model = nonlinear (the "
                            "default) to calibrate in contact");
  check_group_names(parameters);
  c.options.groups =
      checked_fit_groups(parameters, c.variant, request.groups.value_or(defaults.groups));
  c.options.force_weight = defaults.force_weight;
  c.options.max_evaluations = defaults.max_evaluations;
  c.options.tolerance = defaults.tolerance;
  c.options.bound_factor = defaults.bound_factor;
  c.target_damping_ratio = defaults.target_damping_ratio;
  c.options.linear = defaults.model == cases::CalibrationModel::linear;
}

void fit(CaseCalibration& c, const Progress& progress) {
  progress.stage("fitting " + c.variant.name + " (BOBYQA, at most " +
                 std::to_string(c.options.max_evaluations) + " evaluations of " +
                 std::to_string(c.train.size()) + " static solves)");
  const auto fit_start = Clock::now();
  CalibrationOptions options = c.options;
  options.on_evaluation = [&](int evaluation, double) {
    if (evaluation % 20 == 0)
      progress.advance("calibration evaluations (upper bound)", evaluation, options.max_evaluations,
                       seconds_since(fit_start));
  };
  c.fit = calibrate(c.problem, c.mesh, c.variant, c.train, c.test, options);
  if (!c.fit.converged) c.notes.push_back("the optimiser did not converge: " + c.fit.stop_reason);
  if (!c.fit.refit_reason.empty()) c.notes.push_back(c.fit.refit_reason);
  if (const std::string few = loads_with_few_tool_nodes(c.fit.before); !few.empty())
    c.notes.push_back(
        "the tool holds fewer than " + std::to_string(min_tool_patch_nodes) + " surface nodes of " +
        c.variant.name + " at " + few +
        ": such a patch's force grows about linearly with depth while the FEM's resolved contact "
        "grows faster, so no stiffness fits every depth; only a surface fine enough under the "
        "tool for the patch to grow with depth can follow it");
}

// The network with the fit put in, as its simulator loads it: the fitted groups' stiffness (the
// file's times the fitted factor, the case's scale included), and where the file carries its own
// dampers, those of the fitted damping ratio; calibrated.prm runs it in place of the user's file.
void hand_back_network(CaseCalibration& c, const cases::CaseParameters& parameters,
                       const massspring::MassSpringModel& calibrated) {
  const cases::NetworkFile file = cases::read_network(c.variant.network);
  NetworkHandBack h;
  h.original = c.variant.network;
  h.file_name = "calibrated_" + c.variant.name + c.variant.network.extension().string();
  h.stiffness = file.stiffness;
  for (const FittedGroup& g : c.fit.groups) {
    const auto it = std::find(file.group_names.begin(), file.group_names.end(), g.group);
    const int id = static_cast<int>(it - file.group_names.begin());
    for (Eigen::Index s = 0; s < h.stiffness.size(); ++s)
      if (file.spring_group[s] == id) h.stiffness[s] *= g.case_factor;
  }
  if (file.damping && c.damping.reachable)
    h.damping = massspring::damping_for_ratio(calibrated.network(), c.damping.case_damping_ratio);
  std::string networks = "mass spring/networks=";
  for (const auto& n : parameters.mass_spring.networks)
    networks +=
        (&n == &parameters.mass_spring.networks.front() ? "" : "; ") + n.name + "=" +
        (n.name == c.variant.name ? h.file_name : std::filesystem::absolute(n.file).string());
  c.calibrated_overrides.push_back(networks);
  c.hand_back = std::move(h);
}

// The calibrated case as calibrated.prm states it, re-solved from the file's values: it checks
// that the file reproduces the fit, and gives the equilibrium the damping fit linearises about.
void state_calibrated_case(CaseCalibration& c, const cases::CaseParameters& parameters,
                           const CalibrationRequest& request) {
  c.calibrated_overrides = request.overrides;
  c.calibrated_overrides.push_back("calibration/variant=" + c.variant.name);
  Problem calibrated = c.problem;
  calibrated.parameters.mass_spring.group_scales =
      calibrated_group_scales(parameters, c.fit.groups);
  auto written_scales = calibrated.parameters.mass_spring.group_scales;
  if (!c.variant.builtin)  // a network's fitted values go into its own file, not the scales
    written_scales.resize(written_scales.size() - c.fit.groups.size());
  c.calibrated_overrides.push_back(group_scales_assignment(written_scales));
  BuiltVariant built = build_variant(c.variant, calibrated, c.mesh, c.train.front().tool);
  Eigen::VectorXd x;
  const CalibrationErrors check = evaluate_load(c.problem, built, c.train.front(), x);
  c.nonlinear_check = check;
  if (c.options.linear)
    c.notes.push_back(
        "the fit used the spring model linearised at rest; the nonlinear model (as "
        "msfem run solves it) with the fitted values gives rel_l2_error " +
        std::to_string(check.displacement.all.rel_l2_error) + " and reaction_force_rel_error " +
        std::to_string(check.reaction_force_rel_error) + " on " + check.load);
  else if (std::abs(check.displacement.all.rel_l2_error -
                    c.fit.after.train.front().displacement.all.rel_l2_error) >
           1e-6 * std::max(1.0, check.displacement.all.rel_l2_error))
    c.notes.push_back("calibrated.prm re-solved gives rel_l2_error " +
                      std::to_string(check.displacement.all.rel_l2_error) + " on " + check.load +
                      " where the fit had " +
                      std::to_string(c.fit.after.train.front().displacement.all.rel_l2_error));
  // The mode that settles after a press: the static deflection under the first training load.
  c.damping = massspring::fit_damping(*built.model, x, c.target_damping_ratio,
                                      x - built.model->initial_state());
  if (c.damping.reachable) {
    char ratio[64];
    std::snprintf(ratio, sizeof ratio, "%.6g", c.damping.case_damping_ratio);
    c.calibrated_overrides.push_back(std::string("mass spring/damping ratio=") + ratio);
  } else {
    c.notes.push_back(
        "damping: spring dampers cannot give the tool-response mode the target ratio");
  }
  if (!c.variant.builtin) hand_back_network(c, parameters, *built.model);
  const std::string& source = parameters.geometry.source;
  if (cases::is_network_source(source))
    c.calibrated_overrides.push_back(
        "geometry/source=network:" +
        std::filesystem::absolute(cases::network_source_file(source)).string());
  else if (cases::is_image_source(source))
    c.calibrated_overrides.push_back(
        "geometry/source=" +
        cases::image_source_relative_to(source, std::filesystem::current_path()));
  else if (!cases::is_surface_generator(source))
    c.calibrated_overrides.push_back("geometry/source=" +
                                     std::filesystem::absolute(source).string());
  c.lumped_mass_kg = built.model->network().masses.sum();
  c.fem_mass_kg = parameters.material.density_kg_per_m3 * fem_reference::volume(c.mesh);
}

// The case's other variants, as the case has them, on the held-out loads with the fit's model
// (nonlinear or linearised), ranked with the calibrated one.
void compare_on_held_out_loads(CaseCalibration& c, const cases::CaseParameters& parameters,
                               const CalibrationRequest& request, const Progress& progress) {
  c.variants.push_back(mean_on(c.variant.name, true, c.fit.after.test));
  if (request.compare_variants && !c.test.empty()) {
    for (const VariantSpec& spec : variant_specs(parameters)) {
      if (spec.name == c.variant.name) continue;
      const std::string& name = spec.name;
      progress.stage("held-out loads on " + name + " (as the case has it) for comparison");
      BuiltVariant other = build_variant(spec, c.problem, c.mesh, c.test.front().tool);
      std::vector<CalibrationErrors> errors;
      try {
        for (const auto& r : c.test) {
          Eigen::VectorXd xo;
          errors.push_back(c.options.linear ? evaluate_load_linear(c.problem, other, r)
                                            : evaluate_load(c.problem, other, r, xo));
        }
      } catch (const std::runtime_error& e) {
        // A comparison only: say so and go on, the calibration itself stands.
        c.notes.push_back("comparison variant " + name + " left out: " + e.what());
        continue;
      }
      c.variants.push_back(mean_on(name, false, errors));
    }
  }
  std::sort(c.variants.begin(), c.variants.end(),
            [](const auto& a, const auto& b) { return a.mean_rel_l2_error < b.mean_rel_l2_error; });
}

}  // namespace

CaseCalibration calibrate_case(const cases::CaseParameters& parameters,
                               const CalibrationRequest& request) {
  const auto start = Clock::now();
  const Progress progress(request.quiet);
  CaseCalibration c;
  c.variant = resolve_variant(parameters, request);
  const std::vector<cases::ToolLoad> train = request.train.value_or(parameters.calibration.train);
  const std::vector<cases::ToolLoad> test = request.test.value_or(parameters.calibration.test);
  check_loads(parameters, train, test);
  set_options(c, parameters, request);

  progress.stage("loading the surface and placing the tool at every load's position");
  std::vector<cases::ToolLoad> all = train;
  all.insert(all.end(), test.begin(), test.end());
  c.problem = calibration_problem(parameters, all);
  check_distinct_vertices(c.problem, train, test);
  check_variants_fit(c.problem);
  solve_references(c, train, test, request, progress);

  fit(c, progress);
  state_calibrated_case(c, parameters, request);
  compare_on_held_out_loads(c, parameters, request, progress);
  if (c.test.empty()) c.notes.push_back("no held-out loads: the fit is not checked on new loads");
  note_unresolved_loads(c);
  c.total_time_s = seconds_since(start);
  return c;
}

}  // namespace msfem::compare
