// A Young's-modulus field (a CT's) given to a spring network: a uniform field changes nothing,
// and a bar of a soft and a stiff half is those halves in series.
#include <gtest/gtest.h>

#include <cmath>

#include "icosphere.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/modulus_field.hpp"
#include "msfem/massspring/static_solver.hpp"
#include "msfem/massspring/tool_contact.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {
namespace {

// A bar of n × m × m unit cubes (scaled by h), each split into Kuhn's six tetrahedra about the
// same diagonal, so that the cubes' faces match.
void kuhn_bar(int n, int m, double h, Eigen::MatrixX3d& vertices, Eigen::MatrixX4i& tets) {
  auto id = [&](int i, int j, int k) { return i + (n + 1) * (j + (m + 1) * k); };
  vertices.resize((n + 1) * (m + 1) * (m + 1), 3);
  for (int k = 0; k <= m; ++k)
    for (int j = 0; j <= m; ++j)
      for (int i = 0; i <= n; ++i)
        vertices.row(id(i, j, k)) << h * i, h * j, h * k;
  Eigen::MatrixX3d cube;
  Eigen::MatrixX4i cube_tets;
  testing::kuhn_cube(cube, cube_tets);
  tets.resize(6 * n * m * m, 4);
  int t = 0;
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < n; ++i)
        for (int c = 0; c < 6; ++c, ++t)
          for (int corner = 0; corner < 4; ++corner) {
            const Eigen::RowVector3d local = cube.row(cube_tets(c, corner));
            tets(t, corner) = id(i + int(local.x()), j + int(local.y()), k + int(local.z()));
          }
}

// Axial stiffness of the bar: x = 0 clamped, x = L pulled by δ along x (held laterally).
double axial_stiffness(const SpringNetwork& network, double length, double delta) {
  MassSpringModel model(network);
  std::vector<int> pulled;
  for (int node = 0; node < model.num_nodes(); ++node) {
    const double x = network.rest_positions(node, 0);
    if (x < 1e-12 * length) model.fix_node(node);
    if (x > (1 - 1e-12) * length) {
      model.prescribe_displacement(node, Eigen::Vector3d(delta, 0, 0));
      pulled.push_back(node);
    }
  }
  const StaticResult r = solve_static(model);
  EXPECT_TRUE(r.converged);
  return patch_reaction_force(model, r.x, pulled).x() / -delta;
}

TEST(ModulusField, AUniformFieldEqualToTheBuiltModulusChangesNothingBitForBit) {
  const testing::TriangleMesh sphere = testing::icosphere(2, 0.05);
  ThreeTierOptions options;
  options.material.youngs_modulus = 2500.0;
  const SpringNetwork built = build_three_tier(sphere.vertices, sphere.triangles, options);
  SpringNetwork network = built;
  const ModulusRange range = apply_modulus_field(
      network, [](const Eigen::Vector3d&) { return 2500.0; }, 2500.0);
  EXPECT_EQ(range.min, 2500.0);
  EXPECT_EQ(range.max, 2500.0);
  for (int s = 0; s < network.num_springs(); ++s)
    ASSERT_EQ(network.stiffness[s], built.stiffness[s]) << "spring " << s;

  VolumeElements elements =
      tier_prisms(network.rest_positions, sphere.triangles, int(sphere.vertices.rows()), 3, 1234.5);
  const Eigen::VectorXd before = elements.modulus;
  apply_modulus_field(
      elements, network.rest_positions, [](const Eigen::Vector3d&) { return 2500.0; }, 2500.0);
  for (int e = 0; e < elements.num_elements(); ++e)
    ASSERT_EQ(elements.modulus[e], before[e]) << "element " << e;
}

TEST(ModulusField, StiffnessFollowsTheFieldLinearlyAndInSeries) {
  const testing::TriangleMesh sphere = testing::icosphere(1, 0.05);
  const SpringNetwork built = build_single_layer(sphere.vertices, sphere.triangles);
  // E = 3 E_0 everywhere: every spring three times as stiff.
  SpringNetwork tripled = built;
  apply_modulus_field(
      tripled, [](const Eigen::Vector3d&) { return 9000.0; }, 3000.0);
  for (int s = 0; s < built.num_springs(); ++s)
    EXPECT_NEAR(tripled.stiffness[s], 3 * built.stiffness[s], 1e-12 * built.stiffness[s]);
  // A spring half in E_0 and half in 4 E_0 is the two halves in series: 2 k E_0 / (1 + 1/4).
  SpringNetwork split = built;
  const Eigen::Vector3d a = built.rest_positions.row(built.springs(0, 0)).transpose();
  const Eigen::Vector3d b = built.rest_positions.row(built.springs(0, 1)).transpose();
  const Eigen::Vector3d middle = 0.5 * (a + b), axis = b - a;
  const ModulusRange range = apply_modulus_field(
      split,
      [&](const Eigen::Vector3d& x) { return (x - middle).dot(axis) < 0 ? 3000.0 : 12000.0; },
      3000.0);
  EXPECT_NEAR(split.stiffness[0], built.stiffness[0] * 2 / 1.25, 1e-12 * built.stiffness[0]);
  EXPECT_EQ(range.max, 12000.0);
}

TEST(ModulusField, ATwoMaterialBarIsItsHalvesInSeries) {
  // tet_edges on a 20:2:2 bar, soft half E at x < L/2 and stiff half 4E beyond. Each half is the
  // uniform network scaled, so the bar's stiffness is the uniform bar's times
  // L / E_soft / (L/2 / E_soft + L/2 / E_stiff) = 2 / (1 + 1/4) = 1.6, up to the springs in the
  // interface plane and the lateral mismatch of the halves' contraction there.
  const double h = 0.002, length = 20 * h, delta = 1e-5, soft = 3000.0;
  Eigen::MatrixX3d vertices;
  Eigen::MatrixX4i tets;
  kuhn_bar(20, 2, h, vertices, tets);
  TetEdgesOptions options;
  options.material.youngs_modulus = soft;
  const SpringNetwork uniform = build_tet_edges(vertices, tets, options);
  SpringNetwork two_materials = uniform;
  apply_modulus_field(
      two_materials,
      [&](const Eigen::Vector3d& x) { return x.x() < 0.5 * length ? soft : 4 * soft; }, soft);
  const double ratio =
      axial_stiffness(two_materials, length, delta) / axial_stiffness(uniform, length, delta);
  EXPECT_NEAR(ratio, 1.6, 0.02 * 1.6);
}

TEST(ModulusField, ANonPositiveModulusIsRefusedNamingTheSpringAndPoint) {
  const testing::TriangleMesh sphere = testing::icosphere(1, 0.05);
  SpringNetwork network = build_single_layer(sphere.vertices, sphere.triangles);
  try {
    apply_modulus_field(
        network, [](const Eigen::Vector3d& x) { return x.z() > 0 ? -1.0 : 1.0; }, 3000.0);
    FAIL() << "a negative E was accepted";
  } catch (const ModelError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("spring"), std::string::npos) << what;
    EXPECT_NE(what.find("must be finite and > 0"), std::string::npos) << what;
  }
  EXPECT_THROW(apply_modulus_field(
                   network, [](const Eigen::Vector3d&) { return NAN; }, 3000.0),
               ModelError);
}

}  // namespace
}  // namespace msfem::massspring
