// Local surface refinement for the FEM reference near a tool: conforming, shape-preserving,
// angle-bounded, and the input's vertices keep their ids.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "msfem/cases/surface_generators.hpp"
#include "msfem/cases/surface_refinement.hpp"
#include "msfem/cases/surface_validation.hpp"

namespace msfem::cases {
namespace {

double smallest_angle(const Surface& s) {
  double smallest = M_PI;
  for (Eigen::Index t = 0; t < s.num_triangles(); ++t)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d a = s.vertices.row(s.triangles(t, k));
      const Eigen::Vector3d b = s.vertices.row(s.triangles(t, (k + 1) % 3));
      const Eigen::Vector3d c = s.vertices.row(s.triangles(t, (k + 2) % 3));
      smallest = std::min(smallest, std::acos((b - a).normalized().dot((c - a).normalized())));
    }
  return smallest;
}

double longest_edge(const Surface& s, Eigen::Index t) {
  double longest = 0;
  for (int k = 0; k < 3; ++k)
    longest = std::max(
        longest,
        (s.vertices.row(s.triangles(t, k)) - s.vertices.row(s.triangles(t, (k + 1) % 3))).norm());
  return longest;
}

TEST(SurfaceRefinement, RefinesTheBallConformingAndKeepsShapeAndIds) {
  const Surface coarse = icosphere(2, 0.05);  // edges ~ 11 mm
  const RefinementBall ball{Eigen::Vector3d(0, 0, 0.05), 0.01};
  const double max_edge = 0.002;
  const SurfaceRefinement r = refine_near(coarse, {ball}, max_edge);
  const Surface& fine = r.surface;

  ASSERT_GT(r.added_vertices, 20);
  EXPECT_EQ(fine.num_vertices(), coarse.num_vertices() + r.added_vertices);
  EXPECT_TRUE((fine.vertices.topRows(coarse.num_vertices()) - coarse.vertices).isZero(0.0));
  // Closed, manifold, consistently oriented outward, no self-intersections.
  const SurfaceReport report = validate(fine);
  EXPECT_TRUE(report.ok()) << (report.defects.empty() ? "" : report.defects.front().message);
  EXPECT_EQ(report.genus, 0);
  // Flat facets split in their plane: the enclosed volume and the area are unchanged.
  EXPECT_NEAR(signed_volume(fine), signed_volume(coarse), 1e-12 * signed_volume(coarse));
  EXPECT_NEAR(area(fine), area(coarse), 1e-12 * area(coarse));
  // Every triangle with a corner in the ball meets the edge length; far triangles are untouched.
  int in_ball = 0, far_untouched = 0, far = 0;
  for (Eigen::Index t = 0; t < fine.num_triangles(); ++t) {
    double nearest = 1e9;
    for (int k = 0; k < 3; ++k)
      nearest = std::min(
          nearest, (fine.vertices.row(fine.triangles(t, k)).transpose() - ball.center).norm());
    if (nearest <= ball.radius) {
      ++in_ball;
      EXPECT_LE(longest_edge(fine, t), max_edge) << "triangle " << t;
    }
    if (nearest > 0.04) {
      ++far;
      far_untouched += fine.triangles.row(t).maxCoeff() < coarse.num_vertices();
    }
  }
  EXPECT_GT(in_ball, 50);
  EXPECT_EQ(far_untouched, far);
  // Longest-edge bisection keeps the smallest angle above half the input's.
  EXPECT_GE(smallest_angle(fine), 0.5 * smallest_angle(coarse));
}

TEST(SurfaceRefinement, NothingToDoLeavesTheSurfaceAsItIs) {
  const Surface coarse = icosphere(1, 1.0);
  const SurfaceRefinement far = refine_near(coarse, {{Eigen::Vector3d(5, 0, 0), 0.1}}, 0.01);
  EXPECT_EQ(far.added_vertices, 0);
  EXPECT_EQ(far.passes, 0);
  EXPECT_TRUE(far.surface.triangles == coarse.triangles);
  const SurfaceRefinement coarse_enough = refine_near(coarse, {{Eigen::Vector3d(1, 0, 0), 1}}, 10);
  EXPECT_EQ(coarse_enough.added_vertices, 0);
}

TEST(SurfaceRefinement, BadArgumentsAreRefused) {
  const Surface s = icosphere(1, 1.0);
  EXPECT_THROW(refine_near(s, {}, 0.0), std::invalid_argument);
  EXPECT_THROW(refine_near(s, {{Eigen::Vector3d::Zero(), -1.0}}, 0.1), std::invalid_argument);
}

}  // namespace
}  // namespace msfem::cases
