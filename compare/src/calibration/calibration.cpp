#include "msfem/compare/calibration/calibration.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <nlopt.hpp>
#include <stdexcept>

#include "calibration/shared_loads.hpp"
#include "msfem/cases/errors.hpp"
#include "msfem/cases/setting_names.hpp"
#include "msfem/compare/pipeline/case_run.hpp"
#include "msfem/compare/pipeline/metrics.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/linearised_statics.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "pipeline/cholmod_factor.hpp"

namespace msfem::compare {
namespace {

namespace ms = msfem::massspring;
using Clock = std::chrono::steady_clock;

// A value BOBYQA can work with when a static solve fails at a trial point (it cannot take inf):
// far above any objective of a model that solves.
constexpr double failed_objective = 1e6;

std::string stop_reason(nlopt::result r) {
  switch (r) {
    case nlopt::SUCCESS:
      return "success";
    case nlopt::STOPVAL_REACHED:
      return "objective reached the stop value";
    case nlopt::FTOL_REACHED:
      return "objective changed by less than its tolerance";
    case nlopt::XTOL_REACHED:
      return "coefficients moved by less than the tolerance";
    case nlopt::MAXEVAL_REACHED:
      return "evaluation limit reached before convergence";
    case nlopt::MAXTIME_REACHED:
      return "time limit reached before convergence";
    default:
      return "stopped (NLopt result " + std::to_string(static_cast<int>(r)) + ")";
  }
}

bool is_converged(nlopt::result r) {
  return r == nlopt::SUCCESS || r == nlopt::STOPVAL_REACHED || r == nlopt::FTOL_REACHED ||
         r == nlopt::XTOL_REACHED;
}

double objective_of(const std::vector<CalibrationErrors>& errors, double force_weight) {
  double sum = 0;
  for (const auto& e : errors)
    sum += e.displacement.all.rel_l2_error * e.displacement.all.rel_l2_error +
           force_weight * e.reaction_force_rel_error * e.reaction_force_rel_error;
  return sum / static_cast<double>(errors.size());
}

// One model per load (each with its own tool patch and warm start), sharing the stiffness.
struct LoadModels {
  std::vector<BuiltVariant> variants;
  std::vector<Eigen::VectorXd> x;
  /// Solve each load as msfem run does (from rest, a frictionless tool along its path) instead of
  /// from the last evaluation's equilibrium: slower, but on the branch the fitted model will give.
  bool from_rest = true;
  std::vector<std::unique_ptr<ms::LinearisedStatics>> linear;  ///< the fast path, when asked for
};

// The surface nodes a frictionless tool pushes at x (those its contact force reaches).
int nodes_in_contact(const BuiltVariant& variant, const Eigen::VectorXd& x) {
  const auto* contact = variant.model->contact();
  if (!contact || x.size() == 0) return 0;
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  contact->add_force(x, Eigen::VectorXd::Zero(x.size()), f);
  int count = 0;
  for (Eigen::Index i = 0; i < x.size() / 3; ++i)
    count += f.segment<3>(3 * i).squaredNorm() > 0.0;
  return count;
}

// The errors msfem run measures (tet_edges on the FEM's tool-refined mesh has more surface nodes;
// the case's come first), with the nodes under the tool.
CalibrationErrors errors_against(const Problem& problem, const CalibrationLoad& reference,
                                 const Eigen::MatrixX3d& displacement, const Eigen::Vector3d& force,
                                 const BuiltVariant& variant, const Eigen::VectorXd& x = {}) {
  CalibrationErrors e;
  static_cast<LoadErrors&>(e) = load_errors(problem, reference, displacement, force);
  e.load = reference.load.label();
  e.tool_patch_nodes = variant.tool_patch.empty() ? nodes_in_contact(variant, x)
                                                  : static_cast<int>(variant.tool_patch.size());
  return e;
}

LoadModels models_for(const BuiltVariant& base, const std::vector<CalibrationLoad>& references) {
  LoadModels m;
  for (const auto& r : references) {
    BuiltVariant v;
    v.name = base.name;
    v.model = std::make_unique<ms::MassSpringModel>(*base.model);
    v.tool_patch = base.tool_patch;
    v.case_surface_vertices = base.case_surface_vertices;
    set_tool_depth(v, r.placement());
    m.variants.push_back(std::move(v));
    m.x.emplace_back();
  }
  return m;
}

// The load's equilibrium as msfem run reaches it, along the one loading path: an equilibrium
// need not be unique (the shell can turn under an oblique load, a frictionless tool placed at full
// depth at once can slide off), and the path picks the branch a simulator's tool pressed in steps
// follows.
StaticSolution equilibrium_from_rest(BuiltVariant& variant, const CalibrationLoad& reference,
                                     const cases::ToolParameters& tool) {
  // Past the load's depth the path only records run's force-depth curve: calibrate stops there.
  const double depth = reference.placement().depth;
  std::vector<double> path = loading_path(tool, depth);
  path.erase(std::find(path.begin(), path.end(), depth) + 1, path.end());
  return press(variant, reference.tool, path);
}

// The load's equilibrium from `x`, or from rest as msfem run reaches it when `x` is empty.
StaticSolution equilibrium(BuiltVariant& variant, const CalibrationLoad& reference,
                           const Eigen::VectorXd& x, const cases::ToolParameters& tool) {
  if (x.size() == 0) return equilibrium_from_rest(variant, reference, tool);
  set_tool_depth(variant, reference.placement());
  return solve_variant_static(variant, x);
}

// A field at its place in the model's list.
using PlacedField = std::pair<std::size_t, std::shared_ptr<const ms::ForceField>>;

std::vector<CalibrationErrors> evaluate_all(LoadModels& m,
                                            const std::vector<CalibrationLoad>& references,
                                            const Eigen::VectorXd& stiffness,
                                            const std::vector<PlacedField>& fields,
                                            const Problem& problem) {
  return shared_errors(references.size(), [&](std::size_t i) {
    m.variants[i].model->set_stiffness(stiffness);
    for (const auto& [place, field] : fields)
      m.variants[i].model->replace_field(place, field);
    // A frictionless tool's penalty is picked from the stiffness, as msfem run picks it for the
    // fitted model.
    m.variants[i].contact_pressure_penalty = 0.0;
    const StaticSolution s =
        equilibrium(m.variants[i], references[i], m.from_rest ? Eigen::VectorXd() : m.x[i],
                    problem.parameters.loads.tool);
    m.x[i] = s.x;
    return errors_against(problem, references[i], s.surface_displacement, s.tool_force,
                          m.variants[i], s.x);
  });
}

// The groups to fit (all the variant's when none is named), checked against the variant's own:
// its spring groups and its fields' coefficient groups (the volume modulus, a simulator's own
// field's). The linearised fit weighs each field as one part: one fitted group per field.
std::vector<std::string> checked_groups(const BuiltVariant& base, const std::string& file,
                                        const std::string& variant_name,
                                        const CalibrationOptions& options) {
  std::vector<std::string> fittable = base.model->network().spring_group_names;
  for (const auto& field : base.model->fields())
    for (const std::string& group : field->coefficient_groups())
      fittable.push_back(group);
  std::vector<std::string> groups = options.groups;
  if (groups.empty()) groups = fittable;
  std::string known;
  for (const auto& g : fittable)
    known += (known.empty() ? "" : ", ") + g;
  for (const auto& g : groups) {
    const auto count = std::count(fittable.begin(), fittable.end(), g);
    if (count == 0)
      throw cases::InputError(file + ": calibration: variant " + variant_name + " has no group '" +
                              g + "' (its groups: " + known +
                              (g == volume_group ? "; " + std::string(volume_hint) : "") + ")");
    if (count > 1)
      throw cases::InputError(file + ": calibration: variant " + variant_name + " names group '" +
                              g + "' " + std::to_string(count) +
                              " times among its spring groups and fields (its groups: " + known +
                              "): a fit cannot tell which to scale");
  }
  for (const auto& field : base.model->fields()) {
    int fitted = 0;
    for (const std::string& group : field->coefficient_groups())
      fitted += std::count(groups.begin(), groups.end(), group) > 0;
    if (options.linear && fitted > 1)
      throw cases::InputError(file +
                              ": calibration: the linearised fit scales a field as one "
                              "part, and " +
                              field->name() + " has " + std::to_string(fitted) +
                              " groups to fit: fit them without --linear");
  }
  for (std::size_t i = 0; i < groups.size(); ++i)
    if (std::count(groups.begin(), groups.end(), groups[i]) > 1)
      throw cases::InputError(file + ": calibration: group '" + groups[i] + "' is listed twice");
  if (!options.start_factors.empty() && options.start_factors.size() != groups.size())
    throw std::invalid_argument("calibrate: one start factor per fitted group is needed");
  return groups;
}

// The fit's parameters θ: each fitted spring group's stiffness is k_start · exp(θ_g), so it stays
// positive and a factor of 2 too stiff weighs as much as a factor of 2 too soft; a field's group
// (the volume modulus, a simulator's own field's) is scaled uniformly, the case's coefficients
// times the start factor times exp(θ_g). Evaluated on one model per load, nonlinear or linearised
// at rest.
class GroupFit {
 public:
  GroupFit(const Problem& problem, const BuiltVariant& base, std::vector<std::string> groups,
           const CalibrationOptions& options)
      : problem_(problem),
        base_(base),
        network_(base.model->network()),
        groups_(std::move(groups)),
        options_(options),
        n_(static_cast<int>(groups_.size())),
        group_id_(n_, -1),
        field_of_(n_, -1),
        start_factor_(n_, 1.0),
        case_stiffness_(network_.stiffness) {
    const auto& spring_groups = network_.spring_group_names;
    const auto& fields = base.model->fields();
    for (int g = 0; g < n_; ++g) {
      if (!options.start_factors.empty()) start_factor_[g] = options.start_factors[g];
      if (std::find(spring_groups.begin(), spring_groups.end(), groups_[g]) != spring_groups.end())
        group_id_[g] = network_.spring_group_id(groups_[g]);
      for (std::size_t f = 0; f < fields.size() && group_id_[g] < 0; ++f) {
        const std::vector<std::string> named = fields[f]->coefficient_groups();
        if (std::find(named.begin(), named.end(), groups_[g]) != named.end())
          field_of_[g] = static_cast<int>(f);
      }
    }
    start_stiffness_ = case_stiffness_;
    for (int g = 0; g < n_; ++g)
      for (int s = 0; s < network_.num_springs() && group_id_[g] >= 0; ++s)
        if (network_.spring_group[s] == group_id_[g]) start_stiffness_[s] *= start_factor_[g];
  }

  int size() const { return n_; }

  LoadModels models_on(const std::vector<CalibrationLoad>& references) const {
    LoadModels m = models_for(base_, references);
    if (!options_.linear) return m;
    // Part 0: the springs not fitted (weight 1); part g + 1: fitted group g (weight exp θ_g).
    std::vector<Eigen::VectorXd> parts(n_ + 1, Eigen::VectorXd::Zero(network_.num_springs()));
    for (int s = 0; s < network_.num_springs(); ++s) {
      const auto it = std::find(group_id_.begin(), group_id_.end(), network_.spring_group[s]);
      parts[it == group_id_.end() ? 0 : 1 + (it - group_id_.begin())][s] = start_stiffness_[s];
    }
    for (std::size_t i = 0; i < m.variants.size(); ++i)
      m.linear.push_back(owns_load(i) ? std::make_unique<ms::LinearisedStatics>(
                                            *m.variants[i].model, parts, cholmod_factorization())
                                      : nullptr);
    return m;
  }

  std::vector<CalibrationErrors> evaluate(LoadModels& m,
                                          const std::vector<CalibrationLoad>& references,
                                          const std::vector<double>& theta) const {
    if (!options_.linear)
      return evaluate_all(m, references, stiffness_at(theta), fields_at(theta), problem_);
    // Parts: the unfitted springs, each fitted spring group, and each field (LinearisedStatics
    // puts them last); a field group's own spring part stays empty.
    std::vector<double> weights(n_ + 1, 1.0);
    for (int g = 0; g < n_; ++g)
      weights[g + 1] = std::exp(theta[g]);
    for (std::size_t f = 0; f < base_.model->fields().size(); ++f) {
      // The springs are weighed by the parts above, the loads by none.
      const ms::ForceField* field = base_.model->fields()[f].get();
      if (field == &base_.model->springs() || field == &base_.model->loads()) continue;
      double weight = 1.0;
      for (int g = 0; g < n_; ++g)
        if (field_of_[g] == static_cast<int>(f)) weight = factor_at(theta, g);
      weights.push_back(weight);
    }
    return shared_errors(references.size(), [&](std::size_t i) {
      const auto s = m.linear[i]->solve(weights, m.variants[i].tool_patch);
      return errors_against(problem_, references[i], s.surface_displacement, s.patch_force,
                            m.variants[i]);
    });
  }

  /// Each group's start, fitted and case-file values at θ.
  std::vector<FittedGroup> fitted_groups(const std::vector<double>& theta) const {
    const Eigen::VectorXd fitted = stiffness_at(theta);
    std::vector<FittedGroup> result;
    for (int g = 0; g < n_; ++g) {
      FittedGroup f;
      f.group = groups_[g];
      double k_start = 0, k_case = 0, k_fit = 0;
      if (field_of_[g] >= 0) {
        const ms::ForceField& field = *base_.model->fields()[field_of_[g]];
        const std::vector<double> coefficients = field.coefficients(groups_[g]);
        f.spring_group = false;
        f.unit = field.coefficient_unit(groups_[g]);
        f.springs = static_cast<int>(coefficients.size());
        k_case = Eigen::Map<const Eigen::VectorXd>(coefficients.data(), f.springs).sum();
        k_start = k_case * start_factor_[g];
        k_fit = k_case * factor_at(theta, g);
      }
      for (int s = 0; s < network_.num_springs() && group_id_[g] >= 0; ++s)
        if (network_.spring_group[s] == group_id_[g]) {
          ++f.springs;
          k_start += start_stiffness_[s];
          k_case += case_stiffness_[s];
          k_fit += fitted[s];
        }
      f.start_stiffness_n_per_m = k_start / f.springs;
      f.fitted_stiffness_n_per_m = k_fit / f.springs;
      f.factor = k_fit / k_start;
      // The case file's group scale for this group, times what the fit changed from the case.
      double case_scale = 1.0;
      for (const auto& [name, factor] : problem_.parameters.mass_spring.group_scales)
        if (name == groups_[g]) case_scale *= factor;
      f.case_factor = case_scale * k_fit / k_case;
      result.push_back(f);
    }
    return result;
  }

 private:
  Eigen::VectorXd stiffness_at(const std::vector<double>& theta) const {
    Eigen::VectorXd k = start_stiffness_;
    for (int s = 0; s < network_.num_springs(); ++s)
      for (int g = 0; g < n_; ++g)
        if (network_.spring_group[s] == group_id_[g]) k[s] *= std::exp(theta[g]);
    return k;
  }

  // The case's fields whose coefficient groups are fitted, scaled to their factors at θ.
  std::vector<PlacedField> fields_at(const std::vector<double>& theta) const {
    std::vector<PlacedField> scaled;
    for (std::size_t f = 0; f < base_.model->fields().size(); ++f) {
      std::shared_ptr<const ms::ForceField> field = base_.model->fields()[f];
      bool fitted = false;
      for (int g = 0; g < n_; ++g)
        if (field_of_[g] == static_cast<int>(f)) {
          field = field->scaled(groups_[g], factor_at(theta, g));
          fitted = true;
        }
      if (fitted) scaled.emplace_back(f, std::move(field));
    }
    return scaled;
  }

  // A field group's factor on the case's coefficients at θ.
  double factor_at(const std::vector<double>& theta, int g) const {
    return start_factor_[g] * std::exp(theta[g]);
  }

  const Problem& problem_;
  const BuiltVariant& base_;
  const ms::SpringNetwork& network_;
  std::vector<std::string> groups_;
  const CalibrationOptions& options_;
  int n_;
  std::vector<int> group_id_;  ///< spring group id of each fitted group; -1 for a field's group
  std::vector<int> field_of_;  ///< the field (its place in the list) naming a field's group; -1
  std::vector<double> start_factor_;
  Eigen::VectorXd case_stiffness_;   ///< analytic × the case's group scales
  Eigen::VectorXd start_stiffness_;  ///< × the start factors
};

/// The lowest objective seen and where.
struct BestPoint {
  double j;
  std::vector<double> theta;
};

// NLopt's BOBYQA (Sbplx for one group) from `best.theta` on the objective `j`: every evaluation
// goes into fit.history, the lowest into `best`; a trial whose static solve fails gets a large J.
void optimise(const std::function<double(const std::vector<double>&)>& j, BestPoint& best,
              const CalibrationOptions& options, CalibrationFit& fit) {
  const int n = static_cast<int>(best.theta.size());
  auto objective = [&](const std::vector<double>& theta) {
    double value = failed_objective;
    try {
      value = j(theta);
    } catch (const std::runtime_error&) {
      // Newton failed at this trial point: steer the optimiser away from it.
    }
    fit.history.push_back(value);
    if (value < best.j) best = {value, theta};
    if (options.on_evaluation) options.on_evaluation(static_cast<int>(fit.history.size()), value);
    return value;
  };
  using Objective = decltype(objective);
  nlopt::opt opt(n == 1 ? nlopt::LN_SBPLX : nlopt::LN_BOBYQA, static_cast<unsigned>(n));
  const double bound = std::log(options.bound_factor);
  opt.set_lower_bounds(std::vector<double>(n, -bound));
  opt.set_upper_bounds(std::vector<double>(n, bound));
  opt.set_initial_step(std::min(0.5, 0.5 * bound));
  opt.set_xtol_abs(options.tolerance);
  opt.set_maxeval(options.max_evaluations);
  opt.set_min_objective([](const std::vector<double>& theta, std::vector<double>&,
                           void* data) { return (*static_cast<Objective*>(data))(theta); },
                        &objective);
  std::vector<double> theta = best.theta;
  double value = 0;
  try {
    const nlopt::result r = opt.optimize(theta, value);
    fit.converged = is_converged(r);
    fit.stop_reason = stop_reason(r);
  } catch (const nlopt::roundoff_limited&) {
    fit.converged = true;  // no further progress possible at this precision
    fit.stop_reason = "round-off limited: no further progress at double precision";
  } catch (const std::exception& e) {
    fit.converged = false;
    fit.stop_reason = std::string("optimiser failed: ") + e.what();
  }
}

[[noreturn]] void throw_empty_training(const Problem& problem) {
  throw cases::InputError(problem.parameters.file.string() +
                          ": calibration: the training set is empty (give --train or "
                          "calibration/train loads)");
}

}  // namespace

CalibrationErrors evaluate_load(const Problem& problem, BuiltVariant& variant,
                                const CalibrationLoad& reference, Eigen::VectorXd& x) {
  const StaticSolution s = equilibrium(variant, reference, x, problem.parameters.loads.tool);
  x = s.x;
  return errors_against(problem, reference, s.surface_displacement, s.tool_force, variant, s.x);
}

CalibrationErrors evaluate_load_linear(const Problem& problem, BuiltVariant& variant,
                                       const CalibrationLoad& reference) {
  set_tool_depth(variant, reference.placement());
  ms::LinearisedStatics statics(*variant.model, {variant.model->network().stiffness},
                                cholmod_factorization());
  const auto s = statics.solve(std::vector<double>(statics.num_parts(), 1.0), variant.tool_patch);
  return errors_against(problem, reference, s.surface_displacement, s.patch_force, variant);
}

CalibrationFit calibrate(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                         cases::Variant variant, const std::vector<CalibrationLoad>& train,
                         const std::vector<CalibrationLoad>& test,
                         const CalibrationOptions& options) {
  return calibrate(problem, mesh, builtin_spec(variant), train, test, options);
}

CalibrationFit calibrate(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                         const VariantSpec& variant, const std::vector<CalibrationLoad>& train,
                         const std::vector<CalibrationLoad>& test,
                         const CalibrationOptions& options) {
  if (train.empty()) throw_empty_training(problem);
  return calibrate(problem, build_variant(variant, problem, mesh, train.front().placement()), train,
                   test, options);
}

CalibrationFit calibrate(const Problem& problem, const BuiltVariant& base,
                         const std::vector<CalibrationLoad>& train,
                         const std::vector<CalibrationLoad>& test,
                         const CalibrationOptions& options) {
  const auto start = Clock::now();
  const std::string& file = problem.parameters.file.string();
  if (train.empty()) throw_empty_training(problem);
  const GroupFit fitting(problem, base, checked_groups(base, file, base.name, options), options);
  LoadModels train_models = fitting.models_on(train);
  LoadModels test_models = fitting.models_on(test);
  const auto training_objective = [&](const std::vector<double>& theta) {
    return objective_of(fitting.evaluate(train_models, train, theta), options.force_weight);
  };
  CalibrationFit fit;
  const std::vector<double> zero(fitting.size(), 0.0);
  fit.before.train = fitting.evaluate(train_models, train, zero);
  fit.before.test = fitting.evaluate(test_models, test, zero);
  fit.objective_before = objective_of(fit.before.train, options.force_weight);

  // Fast: each trial from the last trial's equilibrium. Then the best point as msfem run solves
  // it; where the trials followed a branch that the fitted model does not reach from rest (the
  // seed's three tiers turning about the core under a frictionless tool), fit again from there
  // with every trial solved from rest.
  BestPoint best{fit.objective_before, zero};
  train_models.from_rest = false;
  optimise(training_objective, best, options, fit);
  fit.warm_started_evaluations = static_cast<int>(fit.history.size());
  train_models.from_rest = true;
  fit.after.train = fitting.evaluate(train_models, train, best.theta);
  fit.objective_after = objective_of(fit.after.train, options.force_weight);
  if (!options.linear && std::abs(fit.objective_after - best.j) > 1e-6 * best.j) {
    fit.refit_reason = "the best warm-started trial (J " + std::to_string(best.j) +
                       ") re-solved from rest gives J " + std::to_string(fit.objective_after) +
                       ": fitted again with every trial solved from rest";
    best = fit.objective_before < fit.objective_after ? BestPoint{fit.objective_before, zero}
                                                      : BestPoint{fit.objective_after, best.theta};
    optimise(training_objective, best, options, fit);
    fit.after.train = fitting.evaluate(train_models, train, best.theta);
    fit.objective_after = objective_of(fit.after.train, options.force_weight);
  }
  fit.evaluations = static_cast<int>(fit.history.size());
  fit.after.test = fitting.evaluate(test_models, test, best.theta);
  fit.test_equilibria = shared_equilibria(test_models.x);
  fit.groups = fitting.fitted_groups(best.theta);
  fit.time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return fit;
}

}  // namespace msfem::compare
