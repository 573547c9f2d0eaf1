// Each bad input gives a clear exception with a one-line message naming the item.

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "msfem/fem_reference/elasticity_problem.hpp"
#include "msfem/fem_reference/errors.hpp"
#include "msfem/fem_reference/supports_and_loads.hpp"
#include "msfem/fem_reference/surface_mesher.hpp"
#include "test_surfaces.hpp"

namespace msfem::fem_reference {
namespace {

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    const testing::TestSurface sphere = testing::icosphere(1, 0.05);
    mesh = mesh_closed_surface(sphere.vertices, sphere.triangles);
    model.material.youngs_modulus = 3e3;
    model.material.poisson_ratio = 0.45;
    model.supports.push_back(fixed_support(
        "bottom", half_space(Eigen::Vector3d(0, 0, -0.04), -Eigen::Vector3d::UnitZ())));
    model.tractions.push_back(
        {"top", half_space(Eigen::Vector3d(0, 0, 0.04), Eigen::Vector3d::UnitZ()), pressure(10.0)});
  }

  /// Runs the problem and returns the message of the exception of type E it must throw.
  template <typename E>
  std::string message_of_run() {
    try {
      ElasticityProblem problem(mesh, model);
      problem.run();
    } catch (const E& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
      return message;
    }
    ADD_FAILURE() << "no exception";
    return {};
  }

  VolumeMesh mesh;
  ElasticityModel model;
};

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST_F(BadInput, NonPositiveYoungsModulus) {
  model.material.youngs_modulus = 0.0;
  EXPECT_TRUE(contains(message_of_run<std::invalid_argument>(), "Young's modulus"));
  model.material.youngs_modulus_field = [](const Eigen::Vector3d& x) {
    return x.z() > 0 ? -1.0 : 1.0;
  };
  EXPECT_TRUE(contains(message_of_run<std::invalid_argument>(), "Young's modulus field"));
}

TEST_F(BadInput, PoissonRatioOutOfRange) {
  for (double nu : {0.5, -1.0, 0.7}) {
    model.material.poisson_ratio = nu;
    EXPECT_TRUE(contains(message_of_run<std::invalid_argument>(), "Poisson's ratio"));
  }
}

TEST_F(BadInput, NoSupportIsSingular) {
  model.supports.clear();
  EXPECT_TRUE(contains(message_of_run<FemError>(), "no support"));
}

TEST_F(BadInput, FixedRegionCatchingNoNode) {
  model.supports.push_back(fixed_support("far_away", ball(Eigen::Vector3d(1, 1, 1), 0.01)));
  EXPECT_TRUE(contains(message_of_run<std::invalid_argument>(), "'far_away' catches no node"));
}

TEST_F(BadInput, TractionCatchingNoFace) {
  model.tractions.push_back({"nowhere", ball(Eigen::Vector3d(1, 1, 1), 0.01), pressure(1.0)});
  EXPECT_TRUE(
      contains(message_of_run<std::invalid_argument>(), "'nowhere' catches no boundary face"));
}

TEST_F(BadInput, SolverNotConverging) {
  model.solver.max_iterations = 2;
  model.solver.relative_tolerance = 1e-14;
  const std::string message = message_of_run<SolverError>();
  EXPECT_TRUE(contains(message, "did not converge")) << message;
  EXPECT_TRUE(contains(message, "after 2 iterations")) << message;
  EXPECT_TRUE(contains(message, "residual norm")) << message;
}

TEST_F(BadInput, UnsupportedDegreeAndOpenSurface) {
  model.degree = 3;
  EXPECT_TRUE(contains(message_of_run<std::invalid_argument>(), "degree"));
  testing::TestSurface sphere = testing::icosphere(1, 0.05);
  sphere.triangles.conservativeResize(sphere.triangles.rows() - 2, 3);
  EXPECT_THROW(mesh_closed_surface(sphere.vertices, sphere.triangles), std::invalid_argument);
  EXPECT_THROW(inner_core(sphere.vertices, sphere.triangles, 2.0), std::invalid_argument);
}

}  // namespace
}  // namespace msfem::fem_reference
