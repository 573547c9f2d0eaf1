#pragma once
// `msfem run`: the FEM once per load and every variant to static equilibrium on the same problem,
// with errors, forces and timings, gathered for the writers (run_outputs.hpp).

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "msfem/compare/pipeline/fem_error_estimate.hpp"
#include "msfem/compare/pipeline/fem_run.hpp"
#include "msfem/compare/pipeline/metrics.hpp"
#include "msfem/compare/pipeline/problem.hpp"
#include "msfem/compare/pipeline/variant_run.hpp"

namespace msfem::compare {

/// Progress lines on stderr ("stage, percent, time left"); silent when quiet.
class Progress {
 public:
  explicit Progress(bool quiet) : quiet_(quiet) {}
  void stage(const std::string& what) const;
  /// Item `done` of `total` finished, `elapsed_s` since the stage began.
  void advance(const std::string& what, int done, int total, double elapsed_s) const;

 private:
  bool quiet_;
};

struct ForceDepthPoint {
  double depth_m = 0.0;
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  std::optional<int> inverted_elements;  ///< a volumetric variant's inverted tetrahedra there
  std::optional<fem_reference::ContactReport> contact;  ///< the FEM's frictionless tool there
};

/// One variant pressed at one of the case's tool positions, at the case's depth, reached along the
/// loading path: alone for the second and later `loads/tool/directions`, within VariantResult for
/// the first.
struct ToolLoadVariant {
  cases::Variant kind = cases::Variant::three_tier;
  std::string name;  ///< kind's name
  ZonedErrorMetrics errors;
  Eigen::Vector3d tool_force = Eigen::Vector3d::Zero();
  double reaction_force_rel_error = 0.0;
  double volume_change = 0.0;
  std::optional<int> inverted_elements;
  std::vector<ForceDepthPoint> force_depth;  ///< every step of its loading path
  std::optional<bool> force_depth_monotone;  ///< along its loading path
  /// With a patch force: the patch's mean displacement (what a force-controlled load measures)
  /// and its error against the FEM's, |ū − ū_FEM| / |ū_FEM|.
  std::optional<Eigen::Vector3d> patch_mean_displacement;
  std::optional<double> patch_displacement_rel_error;
};

/// The variant at the run's own (first) tool position, with what only that load gets.
struct VariantResult : ToolLoadVariant {
  int nodes = 0, springs = 0;
  std::optional<int> refinement_added_nodes;  ///< BuiltVariant's
  Timing timing;
  int newton_iterations = 0;
  nlohmann::json parameters;  ///< group stiffness, damping, masses as used
  std::vector<std::string> warnings;
  Eigen::VectorXd equilibrium;            ///< every node's position at the case's load, m
  Eigen::MatrixX3d surface_displacement;  ///< at the surface vertices, m
  Eigen::MatrixX3d error;                 ///< model − FEM at the surface vertices, m
};

/// The FEM and every variant pressed at problem.tools[tool], tool >= 1 (tool 0 is the run's own
/// load: CaseRun::fem and CaseRun::variants).
struct ToolLoad {
  int tool = 0;
  FemSolution fem;  ///< surface displacement, force and statistics
  std::vector<int> compared_vertices;
  std::vector<ToolLoadVariant> variants;
};

struct CaseRun {
  Problem problem;
  fem_reference::VolumeMesh mesh;
  /// The mesh's worst tetrahedron (fem_reference::cell_quality): CG's iterations follow it.
  std::optional<double> worst_cell_quality;
  FemSolution fem;
  std::vector<ForceDepthPoint> fem_force_depth;
  std::optional<bool> fem_force_depth_monotone;
  std::vector<VariantResult> variants;
  /// Variants whose statics or dynamics failed (a solver, not the input): name and message. The
  /// others are still compared; bad input stops the whole run.
  std::vector<std::pair<std::string, std::string>> failed_variants;
  std::vector<int> compared_vertices;  ///< surface vertices not prescribed by a support or the tool
  std::vector<ToolLoad> other_tools;   ///< the case's second and later tool positions
  FemErrorEstimate fem_error;          ///< the reference's own error, per load
  double wall_time_s = 0.0;
  std::string fem_cache_key;
  bool fem_from_cache = false;
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

/// Force-depth depths of a tool: the case's list, or a quarter, half, three quarters and all of it.
std::vector<double> curve_depths(const cases::ToolParameters& tool);

/// The spring variants' quasi-static loading path: the curve depths and the case's depth in
/// increasing order, with equal steps no longer than `step` (> 0) inserted from 0 up to each.
std::vector<double> loading_path(std::vector<double> depths, double case_depth, double step);

/// The variant at every tool position of the run, in tool order: tool 0 from its own result, then
/// the other tools' (what summary.json's `loads` and report.md's per-tool table show).
std::vector<ToolLoadVariant> per_tool(const CaseRun& run, const VariantResult& variant);

/// The metrics (summary.json names) of `variant` at load `load` that lie within 3x the reference's
/// own estimated error there: the reference does not resolve the variant's error in them.
std::vector<std::string> unresolved_metrics(const CaseRun& run, const ToolLoadVariant& variant,
                                            int load = 0);

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
/// Every buckling warning starts so (msfem run repeats them on stderr).
inline constexpr const char* buckling_warning_start = "buckles under the tool";

}  // namespace msfem::compare
