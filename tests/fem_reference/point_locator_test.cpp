#include "msfem/fem_reference/point_locator.hpp"

#include <gtest/gtest.h>

#include <random>

#include "msfem/fem_reference/closest_point.hpp"
#include "msfem/fem_reference/elasticity_problem.hpp"
#include "msfem/fem_reference/shape_mesher.hpp"
#include "msfem/fem_reference/supports_and_loads.hpp"
#include "msfem/fem_reference/surface_mesher.hpp"
#include "test_surfaces.hpp"

namespace msfem::fem_reference {
namespace {

TEST(PointLocator, FindsTheContainingCellOfRandomPoints) {
  const testing::TestSurface surface = testing::icosphere(2, 1.0);
  const VolumeMesh mesh =
      mesh_closed_surface(surface.vertices, surface.triangles, MeshOptions{0.15, {}, 1});
  const PointLocator locator(mesh);
  std::mt19937 random(42);
  std::uniform_real_distribution<double> coordinate(-0.9, 0.9);
  int checked = 0;
  while (checked < 2000) {
    const Eigen::Vector3d x(coordinate(random), coordinate(random), coordinate(random));
    if (x.norm() > 0.85) continue;  // inside the inscribed polyhedron
    ++checked;
    const PointLocation location = locator.locate(x);
    ASSERT_GE(location.cell, 0);
    EXPECT_EQ(location.distance, 0.0);
    // The exact barycentric test of the returned cell, and the point rebuilt from it.
    EXPECT_GE(locator.barycentric(location.cell, x).minCoeff(), -1e-12);
    Eigen::Vector3d rebuilt = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k)
      rebuilt += location.barycentric[k] *
                 mesh.vertices.row(mesh.tetrahedra(location.cell, k)).transpose();
    EXPECT_LT((rebuilt - x).norm(), 1e-12);
  }
}

TEST(PointLocator, ClampsPointsOutsideToTheNearestCell) {
  const VolumeMesh mesh = mesh_box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1), 0.25);
  const PointLocator locator(mesh);
  const PointLocation above = locator.locate(Eigen::Vector3d(0.3, 0.6, 1.01));
  EXPECT_NEAR(above.distance, 0.01, 1e-12);
  EXPECT_GE(above.barycentric.minCoeff(), 0.0);
  Eigen::Vector3d closest = Eigen::Vector3d::Zero();
  for (int k = 0; k < 4; ++k)
    closest += above.barycentric[k] * mesh.vertices.row(mesh.tetrahedra(above.cell, k)).transpose();
  EXPECT_LT((closest - Eigen::Vector3d(0.3, 0.6, 1.0)).norm(), 1e-12);
  EXPECT_NEAR(locator.locate(Eigen::Vector3d(-1, -1, -1)).distance, std::sqrt(3.0), 1e-12);
}

/// A quadratic displacement with the constant body force that makes it exact (div sigma + b = 0):
/// P2 reproduces it on every cell, so the values at arbitrary points test the reference point and
/// the vertex order used in the evaluation (the cell itself is tested above: a globally quadratic
/// field would hide a wrong but nearby cell).
TEST(PointLocator, EvaluatesAQuadraticFieldInP2AtArbitraryPoints) {
  constexpr double E = 1e4, nu = 0.3, c = 1e-3;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  const VectorField exact = [c](const Eigen::Vector3d& x) -> Eigen::Vector3d {
    return c * Eigen::Vector3d(x.x() * x.x() - x.y() * x.z(), x.x() * x.y(), x.z() * x.z());
  };
  // Computed symbolically: u_x = x^2 - yz, u_y = xy, u_z = z^2 (times c).
  //   div u = 2x + x + 2z = 3x + 2z;  div sigma = (lambda + mu) grad div u + mu lap u
  //   grad div u = (3, 0, 2), lap u = (2, 0, 2)  =>  div sigma = c ((lambda+mu) 3 + 2 mu, 0,
  //   (lambda+mu) 2 + 2 mu)
  const Eigen::Vector3d body_force =
      -c * Eigen::Vector3d(3 * (lambda + mu) + 2 * mu, 0.0, 2 * (lambda + mu) + 2 * mu);
  const testing::TestSurface surface = testing::icosphere(2, 1.0);
  const VolumeMesh mesh =
      mesh_closed_surface(surface.vertices, surface.triangles, MeshOptions{0.2, {}, 1});
  ElasticityModel model;
  model.degree = 2;
  model.material.youngs_modulus = E;
  model.material.poisson_ratio = nu;
  model.body_force = [body_force](const Eigen::Vector3d&) { return body_force; };
  Support boundary = fixed_support(
      "boundary", [](const Eigen::Vector3d&) { return true; }, true);
  boundary.displacement = exact;
  model.supports.push_back(boundary);
  model.solver.preconditioner = Preconditioner::mumps;
  ElasticityProblem problem(mesh, model);
  problem.run();
  EXPECT_LT(problem.max_nodal_error(exact), 1e-12);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  Eigen::MatrixX3d points(500, 3);
  for (Eigen::Index i = 0; i < points.rows();) {
    const Eigen::Vector3d x(coordinate(random), coordinate(random), coordinate(random));
    if (x.norm() < 0.9) points.row(i++) = x.transpose();
  }
  const Eigen::MatrixX3d u = problem.displacements_at(points);
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    EXPECT_LT((u.row(i).transpose() - exact(points.row(i).transpose())).norm(), 1e-12) << i;
  // A point between a curved boundary's facets is clamped to the nearest cell.
  EXPECT_TRUE(problem.displacements_at(Eigen::RowVector3d(0, 0, 1.0)).allFinite());
}

// Each of the seven Voronoi regions of a right triangle, against the closest point by hand; and
// random points against a dense sampling of the triangle.
TEST(ClosestPointOnTriangle, EveryRegionGivesTheClosedFormAndNoSampleIsCloser) {
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const auto at = [&](double x, double y, double z) {
    return closest_point_on_triangle(Eigen::Vector3d(x, y, z), a, b, c);
  };
  EXPECT_LT((at(0.2, 0.3, 1) - Eigen::Vector3d(0.2, 0.3, 0)).norm(), 1e-15);  // face
  EXPECT_EQ(at(-1, -1, 0.5), a);
  EXPECT_EQ(at(2, -1, 0), b);
  EXPECT_EQ(at(-0.5, 3, -1), c);
  EXPECT_LT((at(0.5, -1, 3) - Eigen::Vector3d(0.5, 0, 0)).norm(), 1e-15);    // edge ab
  EXPECT_LT((at(-1, 0.25, 0) - Eigen::Vector3d(0, 0.25, 0)).norm(), 1e-15);  // edge ac
  EXPECT_LT((at(1, 1, 2) - Eigen::Vector3d(0.5, 0.5, 0)).norm(), 1e-15);     // edge bc
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-1.5, 1.5);
  const Eigen::Vector3d b2(0.8, 0.3, 0.4), c2(-0.2, 0.9, -0.3);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d p(coordinate(random), coordinate(random), coordinate(random));
    const double closest = (closest_point_on_triangle(p, a, b2, c2) - p).norm();
    for (int i = 0; i <= 40; ++i)
      for (int j = 0; i + j <= 40; ++j) {
        const Eigen::Vector3d q = a + (b2 - a) * (i / 40.0) + (c2 - a) * (j / 40.0);
        ASSERT_LE(closest, (q - p).norm() + 1e-12);
      }
  }
}

}  // namespace
}  // namespace msfem::fem_reference
