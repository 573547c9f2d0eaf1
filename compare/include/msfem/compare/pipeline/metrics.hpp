#pragma once
// Displacement and force errors of a mass-spring model against the FEM reference, as defined in
// docs/harness.md ("Metrics"): over the surface vertices not prescribed by a support or load.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace msfem::compare {

/// The numbers about a variant at a load that other code names: summary.json's keys, the
/// regression baselines' metrics and the "not resolved by this reference" flags.
enum class Metric {
  rel_l2_error,
  max_error_m,
  reaction_force_rel_error,
  patch_displacement_rel_error,
  volume_change
};
/// Its key in summary.json and the baselines.
const char* metric_name(Metric metric);
/// The names of `metrics`, in their order (summary.json's lists).
std::vector<std::string> metric_names(const std::vector<Metric>& metrics);
bool contains(const std::vector<Metric>& metrics, Metric metric);

struct ErrorMetrics {
  double rel_l2_error = 0.0;              ///< ‖u − v‖₂ / ‖v‖₂
  double rms_error_m = 0.0;               ///< sqrt(mean |u − v|²)
  double max_error_m = 0.0;               ///< max |u − v|
  double mean_error_over_max_disp = 0.0;  ///< mean |u − v| / max |v|
  int vertices = 0;                       ///< how many vertices the figures are over
};

/// Errors of u (model) against v (reference) over the given rows (n x 3 each, metres). Throws
/// std::invalid_argument if the arrays differ in shape, a value is not finite, or the reference
/// does not move at all on those rows (a relative error would be meaningless).
ErrorMetrics displacement_error(const Eigen::MatrixX3d& u, const Eigen::MatrixX3d& v,
                                const std::vector<int>& rows);

/// The same, split by distance from the tool: the contact zone is within `zone_radius` of
/// `tool_point` (DESIGN: 2 r), the far field the rest. An empty zone gives zeros with vertices = 0.
struct ZonedErrorMetrics {
  ErrorMetrics all, contact_zone, far_field;
};
ZonedErrorMetrics zoned_displacement_error(const Eigen::MatrixX3d& u, const Eigen::MatrixX3d& v,
                                           const Eigen::MatrixX3d& rest_positions,
                                           const std::vector<int>& rows,
                                           const Eigen::Vector3d& tool_point, double zone_radius);

/// A model's errors at one load against the reference there (DESIGN's definitions): what msfem
/// run, sweep and calibrate each measure, by load_errors (case_run.hpp).
struct LoadErrors {
  ZonedErrorMetrics displacement;  ///< over the compared surface vertices, and by zone
  Eigen::Vector3d tool_force = Eigen::Vector3d::Zero();
  /// False for an outside simulator's answer that carries no force: the force columns are empty.
  bool force_measured = true;
  double reaction_force_rel_error = 0.0;  ///< with a tool and a measured force; 0 otherwise
};

/// |F_ms − F_fem| / |F_fem|; throws std::invalid_argument if the reference force is zero.
double reaction_force_rel_error(const Eigen::Vector3d& model, const Eigen::Vector3d& reference);

}  // namespace msfem::compare
