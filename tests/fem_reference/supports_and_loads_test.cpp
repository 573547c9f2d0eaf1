#include "msfem/fem_reference/supports_and_loads.hpp"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "test_surfaces.hpp"

namespace msfem::fem_reference {
namespace {

TEST(SupportsAndLoads, InnerCoreIsTheSurfaceScaledAboutItsCentroid) {
  // An ellipsoid-like star-shaped surface: the unit icosphere stretched to semi-axes (2, 1, 0.5)
  // and shifted; its core for divisor 2 has semi-axes (1, 0.5, 0.25) about the same centre.
  testing::TestSurface surface = testing::icosphere(4, 1.0);
  const Eigen::Vector3d axes(2.0, 1.0, 0.5), shift(0.3, -0.2, 0.1);
  for (Eigen::Index i = 0; i < surface.vertices.rows(); ++i)
    surface.vertices.row(i) =
        surface.vertices.row(i).cwiseProduct(axes.transpose()) + shift.transpose();
  const Region core = inner_core(surface.vertices, surface.triangles, 2.0);
  const Eigen::Vector3d center = surface.vertices.colwise().mean().transpose();
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector3d d(unit(random), unit(random), unit(random));
    // Ellipsoidal "radius" of the point relative to the core; the faceting moves the boundary by
    // less than 1 % at this resolution.
    const double rho = (d.cwiseQuotient(axes / 2)).norm();
    if (std::abs(rho - 1.0) < 0.01) continue;
    EXPECT_EQ(core(center + d), rho < 1.0) << d.transpose() << " rho " << rho;
  }
  EXPECT_THROW(inner_core(surface.vertices, surface.triangles, 1.0), std::invalid_argument);
}

TEST(SupportsAndLoads, ToolProjectsPatchNodesOntoThePushedSphere) {
  ToolIndentation tool;
  tool.contact_point = Eigen::Vector3d(0, 0, 1);
  tool.outward_normal = Eigen::Vector3d(0, 0, 2);  // normalised inside
  tool.radius = 0.2;
  tool.depth = 0.05;
  const Support projected = tool_support(tool);
  EXPECT_TRUE(projected.boundary_nodes_only);
  const Eigen::Vector3d center(0, 0, 1.15);
  const Eigen::Vector3d x(0.05, 0.0, 0.99);
  ASSERT_TRUE(projected.region(x));
  EXPECT_NEAR((x + projected.displacement(x) - center).norm(), 0.2, 1e-14);
  EXPECT_FALSE(projected.region(Eigen::Vector3d(0.3, 0, 1.0)));
  EXPECT_NEAR(projected.displacement(Eigen::Vector3d(0, 0, 1)).z(), -0.05, 1e-14);
  tool.mode = ToolPatchMode::uniform;
  const Support uniform = tool_support(tool);
  EXPECT_TRUE(uniform.displacement(x).isApprox(Eigen::Vector3d(0, 0, -0.05)));
  tool.radius = 0.0;
  EXPECT_THROW(tool_support(tool), std::invalid_argument);
}

TEST(SupportsAndLoads, RegionsAndTractions) {
  const Region below = half_space(Eigen::Vector3d(0, 0, -1), -Eigen::Vector3d::UnitZ());
  EXPECT_TRUE(below(Eigen::Vector3d(5, 5, -1)));
  EXPECT_TRUE(below(Eigen::Vector3d(0, 0, -2)));
  EXPECT_FALSE(below(Eigen::Vector3d(0, 0, -0.9)));
  const Region symmetry = plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), 1e-9);
  EXPECT_TRUE(symmetry(Eigen::Vector3d(1e-12, 3, 4)));
  EXPECT_FALSE(symmetry(Eigen::Vector3d(1e-6, 3, 4)));
  EXPECT_TRUE(ball(Eigen::Vector3d::Zero(), 1.0)(Eigen::Vector3d(0.6, 0.8, 0)));
  const Eigen::Vector3d n(0, 1, 0);
  EXPECT_TRUE(pressure(10.0)(Eigen::Vector3d::Zero(), n).isApprox(Eigen::Vector3d(0, -10, 0)));
  EXPECT_THROW(half_space(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()), std::invalid_argument);
}

}  // namespace
}  // namespace msfem::fem_reference
