// The FEM with Young's modulus as a field: a bar of a soft and a stiff half pulled along its axis
// is the two halves in series, A / (L₁/E₁ + L₂/E₂), and reports the E it assembled with.
#include <gtest/gtest.h>

#include <cmath>

#include "msfem/fem_reference/elasticity_problem.hpp"
#include "msfem/fem_reference/shape_mesher.hpp"
#include "msfem/fem_reference/supports_and_loads.hpp"

namespace msfem::fem_reference {
namespace {

// ν = 0: the halves do not contract sideways, so clamping both ends is still uniaxial stress and
// the series formula is the continuum's exact answer; what is left is the discretisation of the
// jump in E inside the cells the interface cuts.
double bar_stiffness(const VolumeMesh& mesh, unsigned degree, const ScalarField& modulus,
                     SolveStatistics* statistics = nullptr) {
  const double length = 0.04, delta = 1e-4;
  ElasticityModel model;
  model.degree = degree;
  model.material.youngs_modulus = 3000;
  model.material.youngs_modulus_field = modulus;
  model.material.poisson_ratio = 0.0;
  model.supports.push_back(
      fixed_support("clamped", plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), 1e-9)));
  Support pulled =
      fixed_support("pulled", plane(Eigen::Vector3d(length, 0, 0), Eigen::Vector3d::UnitX(), 1e-9));
  pulled.displacement = [&](const Eigen::Vector3d&) { return Eigen::Vector3d(delta, 0, 0); };
  model.supports.push_back(pulled);
  ElasticityProblem problem(mesh, model);
  problem.run();
  if (statistics) *statistics = problem.statistics();
  return problem.reaction_force("pulled").x() / delta;  // the support pulls the body along +x
}

TEST(ModulusField, ATwoMaterialBarIsItsHalvesInSeries) {
  const double length = 0.04, width = 0.01, soft = 3000, stiff = 12000;
  const double series = width * width / (0.5 * length / soft + 0.5 * length / stiff);
  const ScalarField two_materials = [&](const Eigen::Vector3d& x) {
    return x.x() < 0.5 * length ? soft : stiff;
  };
  for (const double cell : {0.005, 0.0025}) {
    const VolumeMesh mesh =
        mesh_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(length, width, width), cell);
    SolveStatistics statistics;
    const double k = bar_stiffness(mesh, 2, two_materials, &statistics);
    const double error = std::abs(k / series - 1);
    // 0.41 % and 0.45 % measured: the interface cuts cells of both meshes.
    EXPECT_LT(error, 0.01) << "cell " << cell << ": " << k << " N/m against " << series;
    EXPECT_EQ(statistics.youngs_modulus_min, soft);
    EXPECT_EQ(statistics.youngs_modulus_max, stiff);
    // A uniform field is the uniform bar, E A / L, to the solver's tolerance.
    const double uniform = bar_stiffness(mesh, 2, [&](const Eigen::Vector3d&) { return soft; });
    EXPECT_NEAR(uniform, soft * width * width / length, 1e-6 * uniform);
  }
}

}  // namespace
}  // namespace msfem::fem_reference
