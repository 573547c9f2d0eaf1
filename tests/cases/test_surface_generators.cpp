#include <gtest/gtest.h>

#include <cmath>

#include "msfem/cases/errors.hpp"
#include "msfem/cases/surface_generators.hpp"
#include "msfem/cases/surface_validation.hpp"

namespace msfem::cases {
namespace {

class IcosphereLevel : public ::testing::TestWithParam<int> {};

TEST_P(IcosphereLevel, CountsFollowTheSubdivisionFormulas) {
  const int n = GetParam();
  const Surface s = icosphere(n, 0.05);
  const long four_n = 1L << (2 * n);
  EXPECT_EQ(s.num_vertices(), 10 * four_n + 2);
  EXPECT_EQ(static_cast<long>(unique_edges(s).size()), 30 * four_n);
  EXPECT_EQ(s.num_triangles(), 20 * four_n);

  const SurfaceReport r = validate(s);
  EXPECT_TRUE(r.ok()) << (r.defects.empty() ? "" : r.defects.front().message);
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.components, 1);
  EXPECT_GT(r.volume, 0.0) << "icosphere must be outward oriented";
  // Every vertex lies on the sphere.
  EXPECT_NEAR(s.vertices.rowwise().norm().maxCoeff(), 0.05, 1e-15);
  EXPECT_NEAR(s.vertices.rowwise().norm().minCoeff(), 0.05, 1e-15);
}

INSTANTIATE_TEST_SUITE_P(Levels, IcosphereLevel, ::testing::Range(0, 6));

TEST(Icosphere, SeedSphereIsLevelThree) {
  const Surface s = icosphere(3, 0.05);
  EXPECT_EQ(s.num_vertices(), 642);
  EXPECT_EQ(unique_edges(s).size(), 1920u);
  EXPECT_EQ(s.num_triangles(), 1280);
}

TEST(Icosphere, VolumeConvergesToTheBallAtSecondOrder) {
  const double exact = 4.0 / 3.0 * M_PI;
  double previous_error = 0;
  for (int n = 1; n <= 6; ++n) {
    const double error = exact - signed_volume(icosphere(n, 1.0));
    EXPECT_GT(error, 0.0) << "an inscribed polyhedron is smaller than the ball";
    if (n > 1) {
      // Edge length halves per level and the volume error is O(h^2): the ratio tends to 4
      // (first order would give 2).
      EXPECT_NEAR(previous_error / error, 4.0, 0.4) << "level " << n;
    }
    previous_error = error;
  }
  EXPECT_LT(previous_error / exact, 1e-3);
}

TEST(Ellipsoid, VolumeAndExtentMatchTheSemiAxes) {
  const Eigen::Vector3d axes(0.03, 0.02, 0.01), center(1, 2, 3);
  const Surface s = ellipsoid(5, axes, center);
  EXPECT_NEAR(signed_volume(s), 4.0 / 3.0 * M_PI * axes.prod(), 1e-3 * axes.prod() * 4.19);
  const auto box = bounding_box(s);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(box(1, k) - center[k], axes[k], 1e-12);
    EXPECT_NEAR(center[k] - box(0, k), axes[k], 1e-12);
  }
  EXPECT_TRUE(validate(s).ok());
}

TEST(GenerateSurface, ParsesSpecs) {
  EXPECT_EQ(generate_surface("icosphere:2").num_vertices(), 162);
  EXPECT_NEAR(generate_surface("icosphere:1:0.5").vertices.row(0).norm(), 0.5, 1e-15);
  const Surface e = generate_surface("ellipsoid:2:0.3:0.2:0.1");
  EXPECT_NEAR(bounding_box(e)(1, 0), 0.3, 1e-15);
}

TEST(GenerateSurface, RejectsBadSpecsNamingThem) {
  for (const char* spec : {"cube:3", "icosphere", "icosphere:x", "icosphere:12", "icosphere:3:-1",
                           "icosphere:3:nan", "ellipsoid:3:1:1", "ellipsoid:3:1:0:1"}) {
    try {
      generate_surface(spec);
      ADD_FAILURE() << spec << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(spec), std::string::npos) << e.what();
    }
  }
}

TEST(Icosphere, RejectsBadArguments) {
  EXPECT_THROW(icosphere(-1, 1.0), std::invalid_argument);
  EXPECT_THROW(icosphere(3, 0.0), std::invalid_argument);
  EXPECT_THROW(icosphere(3, std::nan("")), std::invalid_argument);
}

}  // namespace
}  // namespace msfem::cases
