#pragma once

#include <Eigen/Core>
#include <cmath>

namespace msfem::fem_reference {

/// Lame's hollow sphere a <= r <= b: inner surface clamped, outer surface under pressure p.
/// u = u(r) e_r with u(r) = A (r - a^3 / r^2) solves div sigma = 0 and u(a) = 0; the radial stress
///   sigma_rr = (lambda + 2 mu) u' + 2 lambda u / r = A (3K + 4 mu a^3 / r^3)
/// equals -p at r = b for A = -p / (3K + 4 mu a^3 / b^3); the hoop stress is
///   sigma_tt = lambda u' + 2 (lambda + mu) u / r = A (3K - 2 mu a^3 / r^3).
struct LameHollowSphere {
  double inner_radius, outer_radius, pressure, youngs_modulus, poisson_ratio;

  double bulk_modulus() const { return youngs_modulus / (3 * (1 - 2 * poisson_ratio)); }
  double shear_modulus() const { return youngs_modulus / (2 * (1 + poisson_ratio)); }
  double amplitude() const {
    const double ratio = std::pow(inner_radius / outer_radius, 3);
    return -pressure / (3 * bulk_modulus() + 4 * shear_modulus() * ratio);
  }
  double radial_displacement(double r) const {
    return amplitude() * (r - std::pow(inner_radius, 3) / (r * r));
  }
  Eigen::Vector3d displacement(const Eigen::Vector3d& x) const {
    const double r = x.norm();
    return r > 0 ? Eigen::Vector3d(radial_displacement(r) / r * x) : Eigen::Vector3d::Zero();
  }
  double radial_stress(double r) const {
    return amplitude() * (3 * bulk_modulus() + 4 * shear_modulus() * std::pow(inner_radius / r, 3));
  }
  double hoop_stress(double r) const {
    return amplitude() * (3 * bulk_modulus() - 2 * shear_modulus() * std::pow(inner_radius / r, 3));
  }
  /// sigma = sigma_tt I + (sigma_rr - sigma_tt) e_r e_r^T.
  Eigen::Matrix3d stress(const Eigen::Vector3d& x) const {
    const double r = x.norm();
    const Eigen::Vector3d e = x / r;
    return hoop_stress(r) * Eigen::Matrix3d::Identity() +
           (radial_stress(r) - hoop_stress(r)) * e * e.transpose();
  }
};

/// Tip deflection of a cantilever of length L with a rectangular section (height h in the load
/// direction, width w) under an end load P, Timoshenko beam theory:
///   delta = P L^3 / (3 E I) + P L / (kappa G A),  I = w h^3 / 12,  A = w h,
/// with Cowper's shear coefficient of a rectangle kappa = 10 (1 + nu) / (12 + 11 nu).
inline double timoshenko_tip_deflection(double load, double length, double height, double width,
                                        double youngs_modulus, double poisson_ratio) {
  const double I = width * std::pow(height, 3) / 12, A = width * height;
  const double G = youngs_modulus / (2 * (1 + poisson_ratio));
  const double kappa = 10 * (1 + poisson_ratio) / (12 + 11 * poisson_ratio);
  return load * std::pow(length, 3) / (3 * youngs_modulus * I) + load * length / (kappa * G * A);
}

}  // namespace msfem::fem_reference
