// Uniform (red) refinement of a tetrahedral mesh, and the reference's own error estimate it gives:
// the difference between a solve and the same solve on the refined mesh.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "msfem/fem_reference/elasticity_problem.hpp"
#include "msfem/fem_reference/supports_and_loads.hpp"
#include "msfem/fem_reference/surface_mesher.hpp"
#include "msfem/fem_reference/volume_mesh.hpp"
#include "test_surfaces.hpp"

namespace msfem::fem_reference {
namespace {

TEST(RefineUniformly, SplitsEveryCellIntoEightOfTheSameVolumeKeepingTheVertices) {
  const testing::TestSurface surface = testing::icosphere(2, 0.05);
  const VolumeMesh mesh = mesh_closed_surface(surface.vertices, surface.triangles);
  const VolumeMesh fine = refine_uniformly(mesh);
  EXPECT_EQ(fine.num_tetrahedra(), 8 * mesh.num_tetrahedra());
  EXPECT_EQ(fine.num_surface_vertices, mesh.num_surface_vertices);
  EXPECT_TRUE((fine.vertices.topRows(mesh.num_vertices()).array() == mesh.vertices.array()).all());
  EXPECT_NO_THROW(check_volume_mesh(fine));  // every child positively oriented
  EXPECT_NEAR(volume(fine), volume(mesh), 1e-12 * volume(mesh));
  // One shared midpoint per edge of the coarse mesh.
  std::set<std::pair<int, int>> edges;
  for (Eigen::Index e = 0; e < mesh.num_tetrahedra(); ++e)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        edges.insert(std::minmax(mesh.tetrahedra(e, a), mesh.tetrahedra(e, b)));
  EXPECT_EQ(fine.num_vertices(), mesh.num_vertices() + Eigen::Index(edges.size()));
  // Red refinement with the shortest diagonal keeps the children's shape within a fixed factor.
  EXPECT_GT(cell_quality(fine).minCoeff(), 0.3 * cell_quality(mesh).minCoeff());
  const VolumeMesh finer = refine_uniformly(fine);
  EXPECT_GT(cell_quality(finer).minCoeff(), 0.3 * cell_quality(mesh).minCoeff());
}

// A ball with its bottom cap fixed, sagging under gravity: the difference to the solve on the
// refined mesh (the estimate msfem reports as the reference's own error) is within a factor 3 of
// the actual error against a solve two refinements finer, for P1 and P2.
TEST(RefineUniformly, DifferenceToTheRefinedSolveEstimatesTheDiscretisationError) {
  const testing::TestSurface surface = testing::icosphere(2, 0.05);
  MeshOptions options;
  options.cell_size = 0.02;
  const VolumeMesh coarse = mesh_closed_surface(surface.vertices, surface.triangles, options);
  const VolumeMesh fine = refine_uniformly(coarse), finest = refine_uniformly(fine);
  for (unsigned int degree : {1u, 2u}) {
    ElasticityModel model;
    model.degree = degree;
    model.material.youngs_modulus = 3e3;
    model.material.poisson_ratio = 0.3;
    model.material.density = 1000;
    model.material.gravity = Eigen::Vector3d(0, 0, -9.81);
    // The bottom cap fixed (a plane cut, the same node set's limit at every refinement).
    model.supports.push_back(
        fixed_support("base", [](const Eigen::Vector3d& x) { return x.z() < -0.035; }));
    auto surface_displacement = [&](const VolumeMesh& m) {
      ElasticityProblem p(m, model);
      p.run();
      return Eigen::MatrixX3d(p.vertex_displacements().topRows(m.num_surface_vertices));
    };
    const Eigen::MatrixX3d u0 = surface_displacement(coarse), u1 = surface_displacement(fine),
                           u2 = surface_displacement(finest);
    const double estimate = (u0 - u1).norm() / u1.norm();
    const double actual = (u0 - u2).norm() / u2.norm();
    EXPECT_GT(actual, 1e-6) << "degree " << degree;  // a resolvable error, not round-off
    EXPECT_LT(estimate, 3 * actual) << "degree " << degree;
    EXPECT_GT(estimate, actual / 3) << "degree " << degree;
    // The refined solve itself converges: it is closer to the finest than the coarse one is.
    EXPECT_LT((u1 - u2).norm(), 0.7 * (u0 - u2).norm()) << "degree " << degree;
  }
}

}  // namespace
}  // namespace msfem::fem_reference
