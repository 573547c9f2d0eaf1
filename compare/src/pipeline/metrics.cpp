#include "msfem/compare/pipeline/metrics.hpp"

#include <algorithm>

#include <cmath>
#include <stdexcept>
#include <string>

namespace msfem::compare {

const char* metric_name(Metric metric) {
  switch (metric) {
    case Metric::rel_l2_error:
      return "rel_l2_error";
    case Metric::max_error_m:
      return "max_error_m";
    case Metric::reaction_force_rel_error:
      return "reaction_force_rel_error";
    case Metric::patch_displacement_rel_error:
      return "patch_displacement_rel_error";
    case Metric::volume_change:
      return "volume_change";
  }
  return "?";
}

std::vector<std::string> metric_names(const std::vector<Metric>& metrics) {
  std::vector<std::string> names;
  for (const Metric m : metrics)
    names.emplace_back(metric_name(m));
  return names;
}

bool contains(const std::vector<Metric>& metrics, Metric metric) {
  return std::find(metrics.begin(), metrics.end(), metric) != metrics.end();
}

ErrorMetrics displacement_error(const Eigen::MatrixX3d& u, const Eigen::MatrixX3d& v,
                                const std::vector<int>& rows) {
  if (u.rows() != v.rows())
    throw std::invalid_argument("displacement fields differ in size: " + std::to_string(u.rows()) +
                                " vs " + std::to_string(v.rows()) + " vertices");
  ErrorMetrics m;
  if (rows.empty()) return m;
  double error_sq = 0, reference_sq = 0, error_sum = 0, reference_max = 0;
  for (int r : rows) {
    if (r < 0 || r >= u.rows())
      throw std::invalid_argument("vertex " + std::to_string(r) + " out of range");
    if (!u.row(r).allFinite() || !v.row(r).allFinite())
      throw std::invalid_argument("non-finite displacement at surface vertex " + std::to_string(r));
    const double e = (u.row(r) - v.row(r)).norm();
    error_sq += e * e;
    error_sum += e;
    reference_sq += v.row(r).squaredNorm();
    reference_max = std::max(reference_max, v.row(r).norm());
    m.max_error_m = std::max(m.max_error_m, e);
  }
  m.vertices = static_cast<int>(rows.size());
  if (!(reference_max > 0))
    throw std::invalid_argument("the reference does not move on the " +
                                std::to_string(rows.size()) +
                                " compared vertices: no load reaches them");
  m.rel_l2_error = std::sqrt(error_sq / reference_sq);
  m.rms_error_m = std::sqrt(error_sq / static_cast<double>(rows.size()));
  m.mean_error_over_max_disp = error_sum / static_cast<double>(rows.size()) / reference_max;
  return m;
}

ZonedErrorMetrics zoned_displacement_error(const Eigen::MatrixX3d& u, const Eigen::MatrixX3d& v,
                                           const Eigen::MatrixX3d& rest_positions,
                                           const std::vector<int>& rows,
                                           const Eigen::Vector3d& tool_point, double zone_radius) {
  std::vector<int> near, far;
  for (int r : rows)
    ((rest_positions.row(r).transpose() - tool_point).norm() <= zone_radius ? near : far)
        .push_back(r);
  ZonedErrorMetrics z;
  z.all = displacement_error(u, v, rows);
  // An empty zone (a tool bigger than the model) keeps zeros with vertices = 0.
  if (!near.empty()) z.contact_zone = displacement_error(u, v, near);
  if (!far.empty()) z.far_field = displacement_error(u, v, far);
  return z;
}

double reaction_force_rel_error(const Eigen::Vector3d& model, const Eigen::Vector3d& reference) {
  if (!model.allFinite() || !reference.allFinite())
    throw std::invalid_argument("non-finite reaction force");
  if (!(reference.norm() > 0)) throw std::invalid_argument("the reference reaction force is zero");
  return (model - reference).norm() / reference.norm();
}

}  // namespace msfem::compare
