#pragma once
// `msfem calibrate`: per-group spring stiffness fitted so that a variant's static equilibrium
// matches a reference (the FEM) on training tool loads, and checked on held-out loads.
//
// The objective is J(θ) = mean over training loads of e_disp² + w e_force², with e_disp the
// surface rel_l2_error and e_force the reaction_force_rel_error. Under a prescribed tool the
// displacement field depends only on stiffness ratios and the force sets the overall scale, so both
// terms are needed. Stiffness is k_g = k_g,start · exp(θ_g) (positive by construction), and θ is
// found by NLopt's BOBYQA, a bounded derivative-free method (each J is a set of nonlinear static
// solves, warm-started from the previous evaluation's equilibria).

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "msfem/cases/case_parameters.hpp"
#include "msfem/compare/pipeline/fem_error_estimate.hpp"
#include "msfem/compare/pipeline/fem_references.hpp"
#include "msfem/compare/pipeline/metrics.hpp"
#include "msfem/compare/pipeline/problem.hpp"
#include "msfem/compare/pipeline/variant_run.hpp"
#include "msfem/massspring/modal_damping.hpp"

namespace msfem::compare {

/// What the model is compared with on one training or held-out load: the reference there, as
/// msfem run's (its `tool` always set), and the load as the case or command line names it.
struct CalibrationLoad : LoadReference {
  cases::ToolLoad load;
  const ToolPlacement& placement() const { return *tool; }
};

/// The errors of one load, as msfem run measures them, with the load's name and tool patch.
struct CalibrationErrors : LoadErrors {
  std::string load;  ///< ToolLoad::label()
  /// Surface nodes the tool holds (bonded) or pushes (contact) in the spring model at this load.
  /// One node's force grows about
  /// linearly with depth while the FEM's resolved contact grows faster: no stiffness fits every
  /// depth then (docs/calibration.md, "When the surface cannot resolve the tool").
  int tool_patch_nodes = 0;
};

struct ErrorsOnLoads {
  std::vector<CalibrationErrors> train, test;
};

struct FittedGroup {
  std::string group;
  int springs = 0;  ///< springs in the group (a field group: its coefficients, volume elements)
  /// A spring group, or a force field's coefficient group (volume preservation's modulus, a
  /// simulator's own field's), whose "stiffness" is the mean of its coefficients.
  bool spring_group = true;
  /// "N/m" for a spring group; the field's unit for a field group ("Pa" for the volume modulus κ).
  std::string unit = "N/m";
  double start_stiffness_n_per_m = 0.0;  ///< mean over the group's springs, at the start
  double factor = 1.0;                   ///< fitted / start
  double fitted_stiffness_n_per_m = 0.0;
  double case_factor = 1.0;  ///< the factor to write in mass spring/group scales (× the case's)
};

struct CalibrationOptions {
  std::vector<std::string> groups;  ///< empty: every group of the variant
  double force_weight = 1.0;
  int max_evaluations = 400;
  double tolerance = 1e-5;
  double bound_factor = 100.0;
  /// Fit the model linearised at rest (one Cholesky factorisation per load and evaluation) instead
  /// of the nonlinear static equilibrium (Newton): for large models and small indentations.
  bool linear = false;
  /// Starting factors per fitted group (empty: 1, the analytic stiffness).
  std::vector<double> start_factors;
  /// Called after each evaluation with its number and objective (progress reports).
  std::function<void(int, double)> on_evaluation;
};

struct CalibrationFit {
  std::vector<FittedGroup> groups;
  ErrorsOnLoads before, after;
  double objective_before = 0.0, objective_after = 0.0;
  std::vector<double> history;  ///< J of each evaluation, in order
  int evaluations = 0;
  /// The first evaluations, each solved from the last one's equilibrium; the fitted point is then
  /// re-solved as msfem run solves it (from rest), and the rest of `history` is a second fit with
  /// every trial solved so, when the two disagreed (`refit_reason` says by how much).
  int warm_started_evaluations = 0;
  std::string refit_reason;
  bool converged = false;
  std::string stop_reason;  ///< NLopt's, in words
  double time_s = 0.0;
  std::vector<Eigen::VectorXd> test_equilibria;  ///< node-major positions, after the fit
};

/// Fits `variant` built on `problem` (its case's group scales included) to the references.
/// Throws cases::InputError naming `problem.parameters.file` for an unknown group or an empty
/// training set, std::runtime_error if a static solve fails.
CalibrationFit calibrate(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                         const VariantSpec& variant, const std::vector<CalibrationLoad>& train,
                         const std::vector<CalibrationLoad>& test,
                         const CalibrationOptions& options);
CalibrationFit calibrate(const Problem& problem, const fem_reference::VolumeMesh& mesh,
                         cases::Variant variant, const std::vector<CalibrationLoad>& train,
                         const std::vector<CalibrationLoad>& test,
                         const CalibrationOptions& options);
/// The same on a variant already built on `problem` (at the first training load's tool), with
/// whatever fields its model holds: a field a simulator adds is fitted by its coefficient groups
/// like the model's own.
CalibrationFit calibrate(const Problem& problem, const BuiltVariant& base,
                         const std::vector<CalibrationLoad>& train,
                         const std::vector<CalibrationLoad>& test,
                         const CalibrationOptions& options);

/// Errors of a built variant on one reference (its tool set to the reference's), with the static
/// solve warm-started from `x` when it has the right size, else pressed from rest along the case's
/// loading path (loading_path) as msfem run presses; `x` is updated to the equilibrium.
CalibrationErrors evaluate_load(const Problem& problem, BuiltVariant& variant,
                                const CalibrationLoad& reference, Eigen::VectorXd& x);

/// The same on the model linearised at rest (one Cholesky factorisation); throws
/// std::runtime_error where that stiffness is singular.
CalibrationErrors evaluate_load_linear(const Problem& problem, BuiltVariant& variant,
                                       const CalibrationLoad& reference);

}  // namespace msfem::compare
