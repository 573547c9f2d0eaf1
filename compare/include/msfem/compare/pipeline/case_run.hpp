#pragma once
// `msfem run`: the harness's one per-load loop. For each load (each tool position of the case),
// the FEM reference through one cache (fem_references.hpp); for each variant, pressed along the
// loading path at every load and measured against it, and timed; gathered for the writers
// (run_outputs.hpp). msfem sweep and msfem regress consume it as it is.

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "msfem/compare/pipeline/fem_error_estimate.hpp"
#include "msfem/compare/pipeline/fem_references.hpp"
#include "msfem/compare/pipeline/fem_run.hpp"
#include "msfem/compare/pipeline/metrics.hpp"
#include "msfem/compare/pipeline/problem.hpp"
#include "msfem/compare/pipeline/variant_run.hpp"

namespace msfem::compare {

/// One variant pressed at one load of the run (a tool position of the case, at the case's depth,
/// reached along the loading path; or the case's gravity or patch force).
struct ToolLoadVariant : LoadErrors {
  std::string name;  ///< the variant's
  double volume_change = 0.0;
  std::optional<int> inverted_elements;
  std::vector<ForceDepthPoint> force_depth;  ///< every step of its loading path
  std::optional<bool> force_depth_monotone;  ///< along its loading path
  /// No force on the tool where the FEM pushes back: the surface gave way or slid off the sphere,
  /// so the force columns are no answer (marked "lost", warned about).
  bool lost_tool = false;
  /// With a patch force: the patch's mean displacement (what a force-controlled load measures)
  /// and its error against the FEM's, |ū − ū_FEM| / |ū_FEM|.
  std::optional<Eigen::Vector3d> patch_mean_displacement;
  std::optional<double> patch_displacement_rel_error;
  int newton_iterations = 0;
  Eigen::VectorXd equilibrium;            ///< every node's position, m
  Eigen::MatrixX3d surface_displacement;  ///< at the surface vertices, m
  Eigen::MatrixX3d error;                 ///< model − FEM at the surface vertices, m
};

/// What a variant was built with (summary.json's "parameters"): its spring groups as used, its
/// mass and supports, its volume preservation and the E its springs saw; an outside simulator's
/// answer has its files only.
struct VariantParameters {
  struct SpringGroup {
    int springs = 0;
    double mean_stiffness_n_per_m = 0.0, mean_damping_n_s_per_m = 0.0;
  };
  std::map<std::string, SpringGroup> spring_groups;
  double total_mass_kg = 0.0;
  int anchors = 0, constrained_nodes = 0;
  struct Volume {
    int elements = 0;
    double mean_modulus_pa = 0.0;
  };
  std::optional<Volume> volume_preservation;  ///< none: built without it
  double youngs_modulus_min_pa = 0.0, youngs_modulus_max_pa = 0.0;
  std::vector<std::string> external_files;  ///< an outside simulator's answer's (nothing else)
};

/// One variant over the run: what it is, how fast it runs, and its result at every load.
struct VariantResult {
  VariantSpec spec;
  std::string name;  ///< spec's name
  int nodes = 0, springs = 0;
  std::optional<int> refinement_added_nodes;  ///< BuiltVariant's
  Timing timing;                              ///< from its equilibrium at the first load
  VariantParameters parameters;
  std::vector<Warning> warnings;
  std::vector<ToolLoadVariant> loads;  ///< one per CaseRun::loads, in that order
  /// An outside simulator's answer (mass spring/results): no network, nothing timed here.
  bool external = false;
};

struct CaseRun {
  Problem problem;
  fem_reference::VolumeMesh mesh;
  /// The mesh's worst tetrahedron (fem_reference::cell_quality): CG's iterations follow it.
  std::optional<double> worst_cell_quality;
  /// The run's loads, each tool position of the case in order (one load without a tool): the
  /// FEM there, its force-depth curve (the first load's) and its own estimated error. The first is
  /// what summary.json's top-level numbers, report.md's table and the fields show.
  std::vector<LoadReference> loads;
  std::optional<bool> fem_force_depth_monotone;  ///< the first load's FEM curve
  std::vector<VariantResult> variants;
  /// Variants whose statics or dynamics failed (a solver, not the input): name and message. The
  /// others are still compared; bad input stops the whole run.
  std::vector<std::pair<std::string, std::string>> failed_variants;
  FemErrorEstimate fem_error;  ///< how the reference's own error was estimated (values per load)
  double wall_time_s = 0.0;
  bool fem_from_cache = false;  ///< every load's FEM came from the cache
};

struct RunSettings {
  bool quiet = false;
  bool force_depth_curve = true;
  bool time_dynamics = true;
  /// Press at every tool position of the case, each its own load (false: the first only).
  bool all_tools = true;
  /// Where FEM results are cached (none: always solve).
  std::optional<std::filesystem::path> fem_cache_directory;
};

/// Runs the case. Throws cases::InputError for bad input (naming the case file), std::runtime_error
/// when a solver fails.
CaseRun run_case(const cases::CaseParameters& parameters, const RunSettings& settings);

/// The variant's equilibrium with `tool` at its depth. With a path, a quasi-static loading path,
/// each depth started from the last, as a tool pressed in steps is: a network with several
/// equilibria (one that buckles under the tool) then stays on the branch a simulator would follow.
/// Every step is a point of `curve` when one is given (a fall between two curve depths must not go
/// unseen). The path ends at the tool's depth; the variant is left pressed there.
StaticSolution press(BuiltVariant& built, const std::optional<ToolPlacement>& tool,
                     const std::vector<double>& path,
                     std::vector<ForceDepthPoint>* curve = nullptr);

/// An answer at one load measured against the FEM there: the zoned displacement errors, the force
/// and its error (when the answer has a force), the volume change, the patch's mean displacement,
/// whether the force grows along `curve`.
ToolLoadVariant measure_at_load(const Problem& problem, const std::string& name,
                                const Eigen::MatrixX3d& surface_displacement,
                                const std::optional<Eigen::Vector3d>& tool_force,
                                std::vector<ForceDepthPoint> curve, const LoadReference& load);

/// A model's errors at `reference`'s load: its displacement at the case's surface vertices (rows
/// beyond them, a finer surface's, are not compared) and its force on the tool (none: not
/// measured). Throws std::invalid_argument for a displacement with fewer rows or not finite.
LoadErrors load_errors(const Problem& problem, const LoadReference& reference,
                       const Eigen::MatrixX3d& surface_displacement,
                       const std::optional<Eigen::Vector3d>& tool_force);

/// Force-depth depths of a tool: the case's list, or a quarter, half, three quarters and all of it.
std::vector<double> curve_depths(const cases::ToolParameters& tool);

/// The spring variants' quasi-static loading path: the curve depths and the case's depth in
/// increasing order, with equal steps no longer than `step` (> 0) inserted from 0 up to each.
std::vector<double> loading_path(std::vector<double> depths, double case_depth, double step);

/// The largest depth increment of a tool's loading path: the case's path step, and for a
/// frictionless tool at most a quarter of its radius (0: no limit). A frictionless sphere moved
/// further in one static step can pass through the surface or slide off it and leave the network
/// untouched, an equilibrium with no force.
double path_step_of(const cases::ToolParameters& tool);

/// The one loading path of a spring variant (msfem run, sweep and calibrate): a load at `depth` is
/// pressed from rest through the tool's curve depths scaled to it (a quarter, a half, three
/// quarters and all of it when the case lists none), in steps no longer than path_step_of(tool).
/// At the case's own depth the scale is 1: the path passes every curve depth.
std::vector<double> loading_path(const cases::ToolParameters& tool, double depth);

/// The metrics of `variant` at load `load` that lie within 3x the reference's own estimated error
/// there: the reference does not resolve the variant's error in them.
std::vector<Metric> unresolved_metrics(const CaseRun& run, const ToolLoadVariant& variant,
                                       std::size_t load);

/// The exponent n of the power law F = c d^n fitted (least squares in log-log) to the curve's
/// force along the tool's outward normal: 1.5 for Hertz, 1 for a linear spring. None without a
/// tool, with fewer than two points, or where a force does not push the tool back.
std::optional<double> force_depth_exponent(const std::vector<ForceDepthPoint>& curve,
                                           const std::optional<ToolPlacement>& tool);

/// Whether the force the tissue exerts on the tool, along the tool's outward normal, grows strictly
/// from each depth of the curve to the next deeper one; none without a tool or with fewer than
/// two points.
std::optional<bool> force_grows_with_depth(std::vector<ForceDepthPoint> curve,
                                           const std::optional<ToolPlacement>& tool);

/// Where a variant's equilibrium gives way under the tool along its loading path: the first depth
/// at which the force along the tool's outward normal stops growing, and the first at which the
/// lateral reaction exceeds `max_lateral_fraction` of the axial one.
struct BucklingOnset {
  std::optional<double> force_falls_at_m;
  std::optional<double> turns_sideways_at_m;
  double lateral_fraction = 0.0;  ///< lateral / axial where it turned sideways
};
BucklingOnset buckling_onset(std::vector<ForceDepthPoint> curve, const ToolPlacement& tool,
                             double max_lateral_fraction);

/// A variant's lateral reaction may exceed the FEM's own (the surface under the tool need not be
/// flat) by this much of the axial force before the equilibrium counts as turned sideways.
inline constexpr double lateral_fraction_margin = 0.25;

}  // namespace msfem::compare
