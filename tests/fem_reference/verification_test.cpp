// The verification checks behind `msfem verify`, on meshes coarse enough for CI.

#include "msfem/fem_reference/verification.hpp"

#include <gtest/gtest.h>

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
