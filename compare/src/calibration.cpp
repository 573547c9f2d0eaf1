#include "msfem/compare/calibration.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <nlopt.hpp>
#include <stdexcept>

#include "linearised_statics.hpp"
#include "msfem/cases/errors.hpp"
#include "msfem/compare/case_run.hpp"
#include "msfem/compare/metrics.hpp"
#include "msfem/massspring/errors.hpp"

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

double objective_of(const std::vector<LoadErrors>& errors, double force_weight) {
  double sum = 0;
  for (const auto& e : errors)
    sum += e.rel_l2_error * e.rel_l2_error +
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
  std::vector<std::unique_ptr<LinearisedStatics>> linear;  ///< the fast path, when asked for
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

LoadErrors errors_against(const LoadReference& reference, const Eigen::MatrixX3d& displacement,
                          const Eigen::Vector3d& force, const BuiltVariant& variant,
                          const Eigen::VectorXd& x = {}) {
  LoadErrors e;
  e.load = reference.load.label();
  e.tool_patch_nodes = variant.tool_patch.empty() ? nodes_in_contact(variant, x)
                                                  : static_cast<int>(variant.tool_patch.size());
  // tet_edges on the FEM's tool-refined mesh has more surface nodes; the case's come first.
  const Eigen::Index n = reference.surface_displacement.rows();
  if (displacement.rows() < n)
    throw std::invalid_argument("displacement fields differ in size: " +
                                std::to_string(displacement.rows()) + " vs " + std::to_string(n));
  const ErrorMetrics m = displacement_error(displacement.topRows(n), reference.surface_displacement,
                                            reference.compared_vertices);
  e.rel_l2_error = m.rel_l2_error;
  e.mean_error_over_max_disp = m.mean_error_over_max_disp;
  e.tool_force = force;
  e.reaction_force_rel_error = reaction_force_rel_error(force, reference.tool_force);
  return e;
}

LoadModels models_for(const BuiltVariant& base, const std::vector<LoadReference>& references) {
  LoadModels m;
  for (const auto& r : references) {
    BuiltVariant v;
    v.name = base.name;
    v.model = std::make_unique<ms::MassSpringModel>(*base.model);
    v.tool_patch = base.tool_patch;
    v.case_surface_vertices = base.case_surface_vertices;
    set_tool_depth(v, r.tool);
    m.variants.push_back(std::move(v));
    m.x.emplace_back();
  }
  return m;
}

// The load's equilibrium as msfem run reaches it. A frictionless tool's equilibrium need not be
// unique (the shell can turn under an oblique load, or slide off a tool placed at full depth at
// once): it is pressed from rest along quarters of its depth (finer with the case's path step),
// each from the last. A bonded patch is solved from rest at its depth.
StaticSolution equilibrium_from_rest(BuiltVariant& variant, const LoadReference& reference,
                                     double path_step) {
  if (!variant.model->contact()) {
    set_tool_depth(variant, reference.tool);
    return solve_variant_static(variant);
  }
  const double d = reference.tool.depth;
  StaticSolution s;
  for (double depth : loading_path({0.25 * d, 0.5 * d, 0.75 * d}, d, path_step)) {
    set_tool_depth(variant, at_depth(reference.tool, depth));
    s = solve_variant_static(variant, s.x);
  }
  set_tool_depth(variant, reference.tool);
  return s;
}

std::vector<LoadErrors> evaluate_all(LoadModels& m, const std::vector<LoadReference>& references,
                                     const Eigen::VectorXd& stiffness,
                                     const Eigen::VectorXd& volume_modulus, double path_step) {
  std::vector<LoadErrors> errors;
  for (std::size_t i = 0; i < references.size(); ++i) {
    m.variants[i].model->set_stiffness(stiffness);
    if (auto& volume = m.variants[i].model->volume()) volume->set_modulus(volume_modulus);
    // A frictionless tool's penalty is picked from the stiffness, as msfem run picks it for the
    // fitted model.
    m.variants[i].contact_pressure_penalty = 0.0;
    set_tool_depth(m.variants[i], references[i].tool);
    const StaticSolution s = m.from_rest || m.x[i].size() == 0
                                 ? equilibrium_from_rest(m.variants[i], references[i], path_step)
                                 : solve_variant_static(m.variants[i], m.x[i]);
    m.x[i] = s.x;
    errors.push_back(
        errors_against(references[i], s.surface_displacement, s.tool_force, m.variants[i], s.x));
  }
  return errors;
}

// Free dofs of a model (constrained nodes removed) and its restricted matrices.
struct FreeDofs {
  std::vector<int> free_index, full_index;
  explicit FreeDofs(const ms::MassSpringModel& model) : free_index(model.num_dofs(), -1) {
    for (int i = 0; i < model.num_nodes(); ++i)
      if (!model.is_constrained(i))
        for (int c = 0; c < 3; ++c) {
          free_index[3 * i + c] = static_cast<int>(full_index.size());
          full_index.push_back(3 * i + c);
        }
  }
  Eigen::SparseMatrix<double> restrict(const ms::Triplets& all) const {
    ms::Triplets free;
    for (const auto& t : all) {
      const int r = free_index[t.row()], c = free_index[t.col()];
      if (r >= 0 && c >= 0) free.emplace_back(r, c, -t.value());
    }
    const int n = static_cast<int>(full_index.size());
    Eigen::SparseMatrix<double> a(n, n);
    a.setFromTriplets(free.begin(), free.end());
    return a;
  }
};

}  // namespace

LoadErrors evaluate_load(BuiltVariant& variant, const LoadReference& reference, Eigen::VectorXd& x,
                         double path_step) {
  set_tool_depth(variant, reference.tool);
  const StaticSolution s = x.size() == 0 ? equilibrium_from_rest(variant, reference, path_step)
                                         : solve_variant_static(variant, x);
  x = s.x;
  return errors_against(reference, s.surface_displacement, s.tool_force, variant, s.x);
}

LoadErrors evaluate_load_linear(BuiltVariant& variant, const LoadReference& reference) {
  set_tool_depth(variant, reference.tool);
  LinearisedStatics statics(*variant.model, {variant.model->network().stiffness});
  const auto s = statics.solve(std::vector<double>(statics.num_parts(), 1.0), variant.tool_patch);
  return errors_against(reference, s.surface_displacement, s.patch_force, variant);
}

CalibrationFit calibrate(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                         const std::string& variant_name, const std::vector<LoadReference>& train,
                         const std::vector<LoadReference>& test,
                         const CalibrationOptions& options) {
  const auto start = Clock::now();
  const std::string& file = problem.parameters.file.string();
  if (train.empty())
    throw cases::InputError(file +
                            ": calibration: the training set is empty (give --train or "
                            "calibration/train loads)");
  const BuiltVariant base = build_variant(variant_name, problem, mesh, train.front().tool);
  const auto& network = base.model->network();
  // The fittable groups: the spring groups, and the volume modulus when the variant has one.
  std::vector<std::string> fittable = network.spring_group_names;
  if (base.model->volume()) fittable.push_back(volume_group);
  std::vector<std::string> groups = options.groups;
  if (groups.empty()) groups = fittable;
  std::string known;
  for (const auto& g : fittable)
    known += (known.empty() ? "" : ", ") + g;
  for (const auto& g : groups)
    if (std::count(fittable.begin(), fittable.end(), g) != 1)
      throw cases::InputError(file + ": calibration: variant " + variant_name + " has no group '" +
                              g + "' (its groups: " + known +
                              (g == volume_group ? "; " + std::string(volume_hint) : "") + ")");
  for (std::size_t i = 0; i < groups.size(); ++i)
    if (std::count(groups.begin(), groups.end(), groups[i]) > 1)
      throw cases::InputError(file + ": calibration: group '" + groups[i] + "' is listed twice");
  if (!options.start_factors.empty() && options.start_factors.size() != groups.size())
    throw std::invalid_argument("calibrate: one start factor per fitted group is needed");

  const int n = static_cast<int>(groups.size());
  // Spring group id of each fitted group; -1 for the volume group, at index `volume_index`.
  std::vector<int> group_id(n, -1);
  int volume_index = -1;
  for (int g = 0; g < n; ++g) {
    if (groups[g] == volume_group)
      volume_index = g;
    else
      group_id[g] = network.spring_group_id(groups[g]);
  }
  const Eigen::VectorXd case_modulus =
      base.model->volume() ? base.model->volume()->elements().modulus : Eigen::VectorXd();
  const double volume_start_factor = volume_index >= 0 && !options.start_factors.empty()
                                         ? options.start_factors[volume_index]
                                         : 1.0;
  // The volume modulus is scaled uniformly: one factor over the case's, the start's times exp θ.
  auto volume_factor_at = [&](const std::vector<double>& theta) {
    return volume_start_factor * (volume_index >= 0 ? std::exp(theta[volume_index]) : 1.0);
  };
  auto modulus_at = [&](const std::vector<double>& theta) {
    return Eigen::VectorXd(case_modulus * volume_factor_at(theta));
  };
  // The case's stiffness (analytic × its group scales) and the start (× the start factors).
  const Eigen::VectorXd case_stiffness = network.stiffness;
  Eigen::VectorXd start_stiffness = case_stiffness;
  for (int g = 0; g < n; ++g)
    for (int s = 0; s < network.num_springs(); ++s)
      if (network.spring_group[s] == group_id[g] && !options.start_factors.empty())
        start_stiffness[s] *= options.start_factors[g];
  auto stiffness_at = [&](const std::vector<double>& theta) {
    Eigen::VectorXd k = start_stiffness;
    for (int s = 0; s < network.num_springs(); ++s)
      for (int g = 0; g < n; ++g)
        if (network.spring_group[s] == group_id[g]) k[s] *= std::exp(theta[g]);
    return k;
  };

  LoadModels train_models = models_for(base, train);
  LoadModels test_models = models_for(base, test);
  if (options.linear) {
    // Part 0: the springs not fitted (weight 1); part g + 1: fitted group g (weight exp θ_g).
    std::vector<Eigen::VectorXd> parts(n + 1, Eigen::VectorXd::Zero(network.num_springs()));
    for (int s = 0; s < network.num_springs(); ++s) {
      const auto it = std::find(group_id.begin(), group_id.end(), network.spring_group[s]);
      parts[it == group_id.end() ? 0 : 1 + (it - group_id.begin())][s] = start_stiffness[s];
    }
    for (LoadModels* m : {&train_models, &test_models})
      for (const auto& v : m->variants)
        m->linear.push_back(std::make_unique<LinearisedStatics>(*v.model, parts));
  }
  auto evaluate = [&](LoadModels& m, const std::vector<LoadReference>& references,
                      const std::vector<double>& theta) {
    if (!options.linear)
      return evaluate_all(m, references, stiffness_at(theta), modulus_at(theta),
                          problem.parameters.loads.tool.path_step_m);
    // Parts: the unfitted springs, each fitted spring group, and the volume (LinearisedStatics
    // puts it last); the volume group's own part stays empty.
    std::vector<double> weights(n + 1, 1.0);
    for (int g = 0; g < n; ++g)
      weights[g + 1] = std::exp(theta[g]);
    if (base.model->volume()) weights.push_back(volume_factor_at(theta));
    std::vector<LoadErrors> errors;
    for (std::size_t i = 0; i < references.size(); ++i) {
      const auto s = m.linear[i]->solve(weights, m.variants[i].tool_patch);
      errors.push_back(
          errors_against(references[i], s.surface_displacement, s.patch_force, m.variants[i]));
    }
    return errors;
  };
  CalibrationFit fit;
  const std::vector<double> zero(n, 0.0);
  fit.before.train = evaluate(train_models, train, zero);
  fit.before.test = evaluate(test_models, test, zero);
  fit.objective_before = objective_of(fit.before.train, options.force_weight);

  std::vector<double> best_theta(n, 0.0);
  double best = fit.objective_before;
  auto objective = [&](const std::vector<double>& theta) {
    double j = failed_objective;
    try {
      j = objective_of(evaluate(train_models, train, theta), options.force_weight);
    } catch (const std::runtime_error&) {
      // Newton failed at this trial point: steer the optimiser away from it.
    }
    fit.history.push_back(j);
    if (j < best) {
      best = j;
      best_theta = theta;
    }
    if (options.on_evaluation) options.on_evaluation(static_cast<int>(fit.history.size()), j);
    return j;
  };
  using Objective = decltype(objective);
  const auto optimise = [&] {
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
    std::vector<double> theta = best_theta;
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
  };
  // Fast: each trial from the last trial's equilibrium. Then the best point as msfem run solves
  // it; where the trials followed a branch that the fitted model does not reach from rest (the
  // seed's three tiers turning about the core under a frictionless tool), fit again from there
  // with every trial solved from rest.
  train_models.from_rest = false;
  optimise();
  fit.warm_started_evaluations = static_cast<int>(fit.history.size());
  train_models.from_rest = true;
  fit.after.train = evaluate(train_models, train, best_theta);
  fit.objective_after = objective_of(fit.after.train, options.force_weight);
  if (!options.linear && std::abs(fit.objective_after - best) > 1e-6 * best) {
    fit.refit_reason = "the best warm-started trial (J " + std::to_string(best) +
                       ") re-solved from rest gives J " + std::to_string(fit.objective_after) +
                       ": fitted again with every trial solved from rest";
    best = std::min(fit.objective_after, fit.objective_before);
    if (fit.objective_before < fit.objective_after) best_theta = zero;
    optimise();
    fit.after.train = evaluate(train_models, train, best_theta);
    fit.objective_after = objective_of(fit.after.train, options.force_weight);
  }
  fit.evaluations = static_cast<int>(fit.history.size());

  const Eigen::VectorXd fitted = stiffness_at(best_theta);
  fit.after.test = evaluate(test_models, test, best_theta);
  fit.test_equilibria = test_models.x;
  for (int g = 0; g < n; ++g) {
    FittedGroup f;
    f.group = groups[g];
    double k_start = 0, k_case = 0, k_fit = 0;
    if (g == volume_index) {
      f.unit = "Pa";
      f.springs = static_cast<int>(case_modulus.size());
      k_case = case_modulus.sum();
      k_start = k_case * volume_start_factor;
      k_fit = k_case * volume_factor_at(best_theta);
    }
    for (int s = 0; s < network.num_springs() && g != volume_index; ++s)
      if (network.spring_group[s] == group_id[g]) {
        ++f.springs;
        k_start += start_stiffness[s];
        k_case += case_stiffness[s];
        k_fit += fitted[s];
      }
    f.start_stiffness_n_per_m = k_start / f.springs;
    f.fitted_stiffness_n_per_m = k_fit / f.springs;
    f.factor = k_fit / k_start;
    // The case file's group scale for this group, times what the fit changed from the case.
    double case_scale = 1.0;
    for (const auto& [name, factor] : problem.parameters.mass_spring.group_scales)
      if (name == groups[g]) case_scale *= factor;
    f.case_factor = case_scale * k_fit / k_case;
    fit.groups.push_back(f);
  }
  fit.time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return fit;
}

DampingFit fit_damping(const ms::MassSpringModel& model, const Eigen::VectorXd& x, double target,
                       const Eigen::VectorXd& shape) {
  const FreeDofs dofs(model);
  const int n = static_cast<int>(dofs.full_index.size());
  if (n == 0) throw std::invalid_argument("fit_damping: every node is constrained");
  ms::Triplets kt;
  model.add_dfdx_triplets(x, Eigen::VectorXd::Zero(x.size()), kt, ms::Linearisation::exact);
  Eigen::SparseMatrix<double> k = dofs.restrict(kt);
  const Eigen::VectorXd all_mass = model.mass_per_dof();
  Eigen::VectorXd mass(n);
  for (int i = 0; i < n; ++i)
    mass[i] = all_mass[dofs.full_index[i]];
  Eigen::VectorXd v(n);
  double omega2 = 0;
  if (shape.size() == model.num_dofs()) {
    for (int i = 0; i < n; ++i)
      v[i] = shape[dofs.full_index[i]];
    const double norm = std::sqrt(v.dot(mass.cwiseProduct(v)));
    if (!(norm > 0)) throw std::invalid_argument("fit_damping: the mode shape is zero");
    v /= norm;
    omega2 = v.dot(k * v);
  } else {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(k);
    if (ldlt.info() != Eigen::Success || (ldlt.vectorD().array() <= 0).any()) {
      kt.clear();
      model.add_dfdx_triplets(x, Eigen::VectorXd::Zero(x.size()), kt, ms::Linearisation::definite);
      k = dofs.restrict(kt);
      ldlt.compute(k);
      if (ldlt.info() != Eigen::Success)
        throw std::runtime_error("fit_damping: the stiffness at equilibrium is singular");
    }
    // Inverse iteration converges to the mode of the smallest ω² = vᵀKv / vᵀMv.
    v.setOnes();
    for (int it = 0; it < 500; ++it) {
      Eigen::VectorXd y = ldlt.solve(mass.cwiseProduct(v));
      y /= std::sqrt(y.dot(mass.cwiseProduct(y)));
      const double next = y.dot(k * y);
      v = y;
      const bool settled = it > 5 && std::abs(next - omega2) <= 1e-10 * next;
      omega2 = next;
      if (settled) break;
    }
  }
  if (!(omega2 > 0)) throw std::runtime_error("fit_damping: the mode has no stiffness");
  const double omega = std::sqrt(omega2);
  // Modal ratio ζ(r) = vᵀC(r)v / (2ω vᵀMv), with vᵀMv = 1; C is linear in r: ζ(r) = ζ0 + r ζ1.
  auto modal_ratio = [&](double r) {
    ms::MassSpringModel copy = model;
    const auto& net = copy.network();
    Eigen::VectorXd d(net.num_springs());
    for (int s = 0; s < net.num_springs(); ++s) {
      const double ma = net.masses[net.springs(s, 0)], mb = net.masses[net.springs(s, 1)];
      d[s] = 2.0 * r * std::sqrt(net.stiffness[s] * ma * mb / (ma + mb));
    }
    copy.set_damping(d);
    ms::Triplets ct;
    copy.add_dfdv_triplets(x, ct);
    return v.dot(dofs.restrict(ct) * v) / (2.0 * omega);
  };
  DampingFit f;
  f.target = target;
  f.frequency_hz = omega / (2.0 * M_PI);
  const double zeta0 = modal_ratio(0.0);
  f.modal_ratio_per_unit_r = modal_ratio(1.0) - zeta0;
  // Beyond r = 1000 the dampers would dominate every other mode: not a sensible fit.
  f.reachable = f.modal_ratio_per_unit_r > 1e-3 * std::max(target - zeta0, 0.0) && target >= zeta0;
  f.case_damping_ratio = f.reachable ? (target - zeta0) / f.modal_ratio_per_unit_r : 0.0;
  return f;
}

}  // namespace msfem::compare
