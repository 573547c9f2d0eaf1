#include "msfem/massspring/analytic_stiffness.hpp"

#include <cmath>
#include <string>

#include "msfem/massspring/errors.hpp"

namespace msfem::massspring {
namespace {

void check_modulus(double youngs_modulus) {
  if (!(youngs_modulus > 0.0) || !std::isfinite(youngs_modulus))
    throw ModelError("Young's modulus " + std::to_string(youngs_modulus) +
                     " Pa must be finite and > 0");
}

}  // namespace

double lloyd_tet_edge_stiffness(double youngs_modulus, double edge_length) {
  check_modulus(youngs_modulus);
  return 2.0 * std::sqrt(2.0) / 25.0 * youngs_modulus * edge_length;
}

double van_gelder_stiffness(double youngs_modulus, double summed_tet_volume, double edge_length) {
  check_modulus(youngs_modulus);
  return youngs_modulus * summed_tet_volume / (edge_length * edge_length);
}

Eigen::VectorXd isotropic_network_stiffness(double youngs_modulus, double region_volume,
                                            const Eigen::VectorXd& rest_lengths) {
  check_modulus(youngs_modulus);
  const double count = static_cast<double>(rest_lengths.size());
  if (count == 0.0) return Eigen::VectorXd();
  const double volume = std::abs(region_volume);
  return (6.0 * youngs_modulus * volume / count) * rest_lengths.array().square().inverse().matrix();
}

Eigen::VectorXd isotropic_network_stiffness(double youngs_modulus, double region_volume,
                                            const Eigen::VectorXd& rest_lengths,
                                            const Eigen::VectorXd& shares) {
  check_modulus(youngs_modulus);
  if (shares.size() != rest_lengths.size())
    throw ModelError("isotropic network stiffness: " + std::to_string(shares.size()) +
                     " volume shares for " + std::to_string(rest_lengths.size()) + " springs");
  if (rest_lengths.size() == 0) return Eigen::VectorXd();
  if (!shares.allFinite() || !(shares.minCoeff() > 0.0))
    throw ModelError("isotropic network stiffness: volume shares must be finite and > 0");
  const double volume = std::abs(region_volume);
  return (6.0 * youngs_modulus * volume / shares.sum()) *
         (shares.array() / rest_lengths.array().square()).matrix();
}

}  // namespace msfem::massspring
