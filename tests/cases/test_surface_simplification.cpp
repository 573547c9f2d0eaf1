#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "msfem/cases/surface_generators.hpp"
#include "msfem/cases/surface_io.hpp"
#include "msfem/cases/surface_simplification.hpp"
#include "msfem/cases/surface_validation.hpp"
#include "surface_fixtures.hpp"

namespace msfem::cases {
namespace {

void expect_closed_manifold_genus0(const Surface& s) {
  const SurfaceReport r = validate(s);  // self-intersections included: folds are the usual failure
  for (const auto& d : r.defects)
    ADD_FAILURE() << d.message;
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.components, 1);
  EXPECT_GT(r.volume, 0);
}

TEST(Simplify, IcosphereReachesTheTargetExactlyAndStaysClosed) {
  const Surface sphere = icosphere(4, 0.05);
  const Surface coarse = simplify(sphere, 500);
  EXPECT_EQ(coarse.num_vertices(), 500);
  EXPECT_EQ(coarse.num_triangles(), 2 * 500 - 4);  // Euler: F = 2V - 4 for genus 0
  expect_closed_manifold_genus0(coarse);
  // Lindstrom-Turk placement preserves volume to first order.
  EXPECT_NEAR(signed_volume(coarse) / signed_volume(sphere), 1.0, 0.01);
}

TEST(Simplify, PancreasToTheSkeletonPapersFourHundredFortySix) {
  const Surface pancreas =
      read_surface(std::string(MSFEM_CASES_DIR) + "/data/pancreas_vh_female_m.obj");
  const Surface coarse = simplify(pancreas, 446);
  EXPECT_EQ(coarse.num_vertices(), 446);
  expect_closed_manifold_genus0(coarse);
  EXPECT_NEAR(signed_volume(coarse) / signed_volume(pancreas), 1.0, 0.05);
}

TEST(Simplify, BrainToTheSeedsNineThousandPerTier) {
  const Surface brain = read_surface(std::string(MSFEM_CASES_DIR) + "/data/brain_icbm152_lh_mm.obj",
                                     LengthUnit::millimetre);
  const Surface coarse = simplify(brain, 9177);
  EXPECT_EQ(coarse.num_vertices(), 9177);
  expect_closed_manifold_genus0(coarse);
  EXPECT_NEAR(signed_volume(coarse) / signed_volume(brain), 1.0, 0.01);
}

TEST(Simplify, RejectsOpenSurfacesAndImpossibleTargets) {
  Surface open = icosphere(2, 1.0);
  open.triangles.conservativeResize(open.num_triangles() - 1, 3);
  EXPECT_THROW(simplify(open, 50), std::invalid_argument);
  EXPECT_THROW(simplify(icosphere(2, 1.0), 500), std::invalid_argument);
  EXPECT_THROW(simplify(icosphere(2, 1.0), 3), std::invalid_argument);
}

TEST(SmoothTaubin, RemovesNoiseWithoutShrinking) {
  const Surface clean = icosphere(4, 1.0);
  Surface noisy = clean;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (Eigen::Index i = 0; i < noisy.num_vertices(); ++i)
    noisy.vertices.row(i) *= 1.0 + noise(rng);
  // Smoothing also moves the clean sphere's vertices a little; the noise left is what separates
  // the smoothed noisy surface from the smoothed clean one.
  auto rms_distance = [](const Surface& a, const Surface& b) {
    return std::sqrt((a.vertices - b.vertices).rowwise().squaredNorm().mean());
  };
  Surface smoothed = noisy, smoothed_clean = clean;
  smooth_taubin(smoothed, 10);
  smooth_taubin(smoothed_clean, 10);
  EXPECT_LT(rms_distance(smoothed, smoothed_clean), 0.5 * rms_distance(noisy, clean));
  EXPECT_NEAR(signed_volume(smoothed) / signed_volume(clean), 1.0, 0.01);

  // Plain Laplacian smoothing (mu = 0) of the same strength shrinks the ball far more.
  Surface laplacian = noisy;
  smooth_taubin(laplacian, 10, 0.5, 0.0);
  EXPECT_LT(signed_volume(laplacian) / signed_volume(clean), 0.97);
  EXPECT_EQ(smoothed.triangles, noisy.triangles);
}

}  // namespace
}  // namespace msfem::cases
