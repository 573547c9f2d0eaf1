// The verification checks behind `msfem verify`, on meshes coarse enough for CI.

#include "msfem/fem_reference/verification.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <functional>

#include "msfem/fem_reference/closed_forms.hpp"

namespace msfem::fem_reference {
namespace {

TEST(ClosedForms, LameRadialStressMatchesThePressureAndTheInnerSurfaceIsClamped) {
  const LameHollowSphere lame{0.5, 1.0, 1e3, 1e5, 0.3};
  EXPECT_NEAR(lame.radial_stress(1.0), -1e3, 1e-9);
  EXPECT_NEAR(lame.radial_displacement(0.5), 0.0, 1e-15);
  // sigma_rr from a finite-difference u' agrees with the closed form at an interior radius.
  const double r = 0.7, h = 1e-6;
  const double lambda = 1e5 * 0.3 / (1.3 * 0.4), mu = 1e5 / 2.6;
  const double du = (lame.radial_displacement(r + h) - lame.radial_displacement(r - h)) / (2 * h);
  EXPECT_NEAR((lambda + 2 * mu) * du + 2 * lambda * lame.radial_displacement(r) / r,
              lame.radial_stress(r), 1e-5);
  EXPECT_NEAR(lambda * du + 2 * (lambda + mu) * lame.radial_displacement(r) / r,
              lame.hoop_stress(r), 1e-5);
}

/// div sigma of a displacement field by central differences of second order (x in metres).
Eigen::Vector3d divergence_of_stress(const std::function<Eigen::Vector3d(Eigen::Vector3d)>& u,
                                     const Eigen::Vector3d& x, double E, double nu, double h) {
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  const auto stress = [&](const Eigen::Vector3d& y) {
    Eigen::Matrix3d gradient;
    for (int j = 0; j < 3; ++j)
      gradient.col(j) =
          (u(y + h * Eigen::Vector3d::Unit(j)) - u(y - h * Eigen::Vector3d::Unit(j))) / (2 * h);
    const Eigen::Matrix3d strain = 0.5 * (gradient + gradient.transpose());
    return Eigen::Matrix3d(lambda * strain.trace() * Eigen::Matrix3d::Identity() + 2 * mu * strain);
  };
  Eigen::Vector3d divergence = Eigen::Vector3d::Zero();
  for (int j = 0; j < 3; ++j)
    divergence += (stress(x + h * Eigen::Vector3d::Unit(j)).col(j) -
                   stress(x - h * Eigen::Vector3d::Unit(j)).col(j)) /
                  (2 * h);
  return divergence;
}

TEST(ClosedForms, BoussinesqSolvesNaviersEquationsWithATractionFreeSurface) {
  const double E = 3e3, nu = 0.45, P = 1e-3;
  const auto u = [&](const Eigen::Vector3d& x) { return boussinesq_displacement(P, E, nu, x); };
  const Eigen::Vector3d x(0.004, -0.003, -0.005);
  // Its terms are of order P / |x|^3 (3,000 Pa/m here); they cancel to the differences' error.
  const Eigen::Vector3d divergence = divergence_of_stress(u, x, E, nu, 1e-5);
  EXPECT_LT(divergence.norm(), 1e-4 * P / std::pow(x.norm(), 3)) << divergence.transpose();
  // Off the axis the surface is traction-free: sigma e_z = 0 at z = 0 (one-sided in z).
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu)), h = 1e-7;
  const Eigen::Vector3d surface(0.003, 0.002, 0.0);
  Eigen::Matrix3d gradient;
  for (int j = 0; j < 2; ++j)
    gradient.col(j) =
        (u(surface + h * Eigen::Vector3d::Unit(j)) - u(surface - h * Eigen::Vector3d::Unit(j))) /
        (2 * h);
  gradient.col(2) = (u(surface) - u(surface - h * Eigen::Vector3d::UnitZ())) / h;
  const Eigen::Matrix3d strain = 0.5 * (gradient + gradient.transpose());
  const Eigen::Vector3d traction =
      (lambda * strain.trace() * Eigen::Matrix3d::Identity() + 2 * mu * strain).col(2);
  const double stress_scale = P / surface.squaredNorm();
  EXPECT_LT(traction.norm(), 1e-3 * stress_scale) << traction.transpose();
}

TEST(ClosedForms, SneddonsSphereTendsToHertzAndIsSofterAtDepth) {
  const SphereOnHalfSpace contact{5e-3, 3e3, 0.45};
  const double shallow = 1e-4 * 5e-3;
  EXPECT_NEAR(contact.sneddon_force(shallow) / contact.hertz_force(shallow), 1.0, 1e-4);
  EXPECT_NEAR(contact.sneddon_contact_radius(shallow) / contact.hertz_contact_radius(shallow), 1.0,
              1e-4);
  // At d/R = 0.1 the exact sphere is 1.0 % softer than the paraboloid.
  const double deep = 0.1 * 5e-3;
  EXPECT_NEAR(contact.sneddon_force(deep) / contact.hertz_force(deep), 0.990, 1e-3);
  const double a = contact.sneddon_contact_radius(deep);
  EXPECT_NEAR(0.5 * a * std::log((5e-3 + a) / (5e-3 - a)), deep, 1e-12);
}

TEST(Verification, FrictionlessSphereContactConvergesToHertzAtP2) {
  const VerificationCheck check = check_hertz_contact(2, {0.05}, {2.0, 4.0});
  ASSERT_EQ(check.contact.size(), 1u);
  const ContactRow& row = check.contact[0];
  EXPECT_NEAR(row.force / row.hertz_force, 1.0, 0.02);
  EXPECT_NEAR(row.contact_radius / row.sneddon_contact_radius, 1.0, 0.05);
  ASSERT_TRUE(check.observed_order.has_value());
  EXPECT_GT(*check.observed_order, 1.0);
  // The penalty's penetration bound: a few ten-thousandths of the depth.
  EXPECT_LT(row.max_penetration, 1e-3 * 0.05 * 5e-3);
  EXPECT_LE(row.iterations, 10);
  EXPECT_GT(row.active_nodes, 10);
}

TEST(Verification, BondedPatchUnderestimatesTheHertzForce) {
  const VerificationCheck check = check_hertz_bonded({0.02}, 4.0);
  ASSERT_EQ(check.contact.size(), 1u);
  const double ratio = check.contact[0].force / check.contact[0].hertz_force;
  EXPECT_GT(ratio, 0.4);
  EXPECT_LT(ratio, 0.75);
}

TEST(Verification, PatchTestReproducesALinearField) {
  const VerificationCheck check = check_patch();
  EXPECT_TRUE(check.passed) << check.rel_l2_error;
  EXPECT_LT(check.rel_l2_error, 1e-10);
}

TEST(Verification, LameP2ConvergesAtThirdOrder) {
  const VerificationCheck check = check_lame(2, 0.3, {0.25, 0.125});
  ASSERT_TRUE(check.observed_order.has_value());
  EXPECT_GE(*check.observed_order, 2.5);
  EXPECT_LT(check.rel_l2_error, 5e-3);
}

TEST(Verification, LameP1ConvergesAtSecondOrder) {
  const VerificationCheck check = check_lame(1, 0.45, {0.2, 0.1});
  ASSERT_TRUE(check.observed_order.has_value());
  EXPECT_GE(*check.observed_order, 1.8);
}

TEST(Verification, CantileverP2MatchesTimoshenko) {
  const VerificationCheck check = check_cantilever(0.05);
  EXPECT_TRUE(check.passed) << check.note;
}

TEST(Verification, P1LocksAsPoissonsRatioApproachesOneHalf) {
  const std::vector<LockingRow> rows = locking_table(0.2, {0.3, 0.499});
  ASSERT_EQ(rows.size(), 2u);
  // P1's error grows several-fold; P2 at nu = 0.499 stays below P1 at nu = 0.3.
  EXPECT_GT(rows[1].p1_rel_l2_error, 5 * rows[0].p1_rel_l2_error);
  EXPECT_LT(rows[1].p2_rel_l2_error, rows[0].p1_rel_l2_error);
}

}  // namespace
}  // namespace msfem::fem_reference
