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

/// A rigid frictionless sphere of radius R pressed d into a linear elastic half-space, with the
/// plane-strain modulus E* = E / (1 - nu^2).
///  - Hertz (the sphere as a paraboloid, small d/R): a = sqrt(R d), F = 4/3 E* sqrt(R) d^(3/2).
///  - Sneddon (1965, the exact sphere profile): d = a/2 ln((R + a)/(R - a)),
///    F = E*/2 [(a^2 + R^2) ln((R + a)/(R - a)) - 2 a R]; it tends to Hertz as d/R -> 0.
struct SphereOnHalfSpace {
  double radius, youngs_modulus, poisson_ratio;

  double reduced_modulus() const { return youngs_modulus / (1 - poisson_ratio * poisson_ratio); }
  double hertz_contact_radius(double depth) const { return std::sqrt(radius * depth); }
  double hertz_force(double depth) const {
    return 4.0 / 3.0 * reduced_modulus() * std::sqrt(radius) * std::pow(depth, 1.5);
  }
  static double log_ratio(double a, double R) { return std::log((R + a) / (R - a)); }
  /// a with a/2 ln((R + a)/(R - a)) = d, by bisection (the left side grows with a on (0, R)).
  double sneddon_contact_radius(double depth) const {
    double low = 0.0, high = radius * (1 - 1e-15);
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (low + high);
      (0.5 * mid * log_ratio(mid, radius) < depth ? low : high) = mid;
    }
    return 0.5 * (low + high);
  }
  double sneddon_force(double depth) const {
    const double a = sneddon_contact_radius(depth), R = radius;
    return 0.5 * reduced_modulus() * ((a * a + R * R) * log_ratio(a, R) - 2 * a * R);
  }
};

/// Boussinesq's point force P on the surface z = 0 of the half-space z <= 0, pushing in -z, at
/// the origin (Johnson, Contact Mechanics, eq. 3.20 with depth s = -z):
///   u_s = P/(4 pi G) [s^2/rho^3 + 2 (1 - nu)/rho],
///   u_r = P/(4 pi G) [r s/rho^3 - (1 - 2 nu) r/(rho (rho + s))]
/// (u_s into the body, u_r away from the axis). Far from a contact of total force P it is the
/// contact's displacement, which is how a finite block stands in for the half-space.
inline Eigen::Vector3d boussinesq_displacement(double force, double youngs_modulus,
                                               double poisson_ratio, const Eigen::Vector3d& x) {
  const double G = youngs_modulus / (2 * (1 + poisson_ratio)), s = -x.z();
  const double r = std::hypot(x.x(), x.y()), rho = x.norm();
  const double scale = force / (4 * M_PI * G);
  const double u_s = scale * (s * s / (rho * rho * rho) + 2 * (1 - poisson_ratio) / rho);
  const double u_r =
      scale * (r * s / (rho * rho * rho) - (1 - 2 * poisson_ratio) * r / (rho * (rho + s)));
  const Eigen::Vector3d radial =
      r > 0.0 ? Eigen::Vector3d(x.x() / r, x.y() / r, 0.0) : Eigen::Vector3d::Zero();
  return u_r * radial - u_s * Eigen::Vector3d::UnitZ();
}

}  // namespace msfem::fem_reference
