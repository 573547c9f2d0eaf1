// Force model: finite-difference Jacobians for every spring type, momentum balance, energies.

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "force_jacobian_check.hpp"
#include "icosphere.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {
namespace {

using testing::check_force_jacobians;
using testing::icosphere;
using testing::perturbed;

void expect_jacobians_match(const ForceModel& model, const Eigen::VectorXd& x,
                            const Eigen::VectorXd& v) {
  const auto errors = check_force_jacobians(model, x, v, 1e-7);
  EXPECT_LE(errors.dfdx_matrix, 1e-6);
  EXPECT_LE(errors.dfdx_product, 1e-6);
  EXPECT_LE(errors.dfdv_matrix, 1e-6);
  EXPECT_LE(errors.dfdv_product, 1e-6);
  EXPECT_LE(errors.energy_gradient, 1e-6);
}

Material damped_material() {
  Material material;
  material.youngs_modulus = 3000.0;
  material.spring_damping = 0.05;
  material.node_damping = 0.01;
  return material;
}

// A perturbation of 20 % of the mean spring length leaves both stretched and compressed springs.
TEST(ForceJacobians, ThreeTierSpringsWithDampers) {
  const auto mesh = icosphere(1, 0.05);
  ThreeTierOptions options;
  options.material = damped_material();
  const SpringNetwork network = build_three_tier(mesh.vertices, mesh.triangles, options);
  const SpringForceField springs(network);
  const double scale = 0.2 * network.rest_length.mean();
  const Eigen::VectorXd x = perturbed(flatten(network.rest_positions), scale, 1);
  const Eigen::VectorXd v = perturbed(Eigen::VectorXd::Zero(x.size()), 0.1, 2);
  expect_jacobians_match(springs, x, v);
}

TEST(ForceJacobians, SingleLayerWithAnchorSprings) {
  const auto mesh = icosphere(1, 0.05);
  SingleLayerOptions options;
  options.material = damped_material();
  const SpringNetwork network = build_single_layer(mesh.vertices, mesh.triangles, options);
  ASSERT_EQ(network.num_anchors(), network.num_nodes());
  const Eigen::VectorXd x = perturbed(flatten(network.rest_positions), 0.003, 3);
  const Eigen::VectorXd v = perturbed(Eigen::VectorXd::Zero(x.size()), 0.1, 4);
  expect_jacobians_match(SpringForceField(network), x, v);
}

TEST(ForceJacobians, TetEdgesAndSkeleton) {
  Eigen::MatrixX3d cube;
  Eigen::MatrixX4i tets;
  testing::kuhn_cube(cube, tets);
  TetEdgesOptions tet_options;
  tet_options.material = damped_material();
  const SpringNetwork tet_network = build_tet_edges(0.01 * cube, tets, tet_options);
  Eigen::VectorXd x = perturbed(flatten(tet_network.rest_positions), 0.002, 5);
  Eigen::VectorXd v = perturbed(Eigen::VectorXd::Zero(x.size()), 0.1, 6);
  expect_jacobians_match(SpringForceField(tet_network), x, v);

  const auto surface = icosphere(1, 0.05);
  const auto control = icosphere(0, 0.05);
  SkeletonOptions skeleton_options;
  skeleton_options.material = damped_material();
  const SpringNetwork skeleton = build_skeleton(
      surface.vertices, surface.triangles, control.vertices, control.triangles, skeleton_options);
  x = perturbed(flatten(skeleton.rest_positions), 0.003, 7);
  v = perturbed(Eigen::VectorXd::Zero(x.size()), 0.1, 8);
  expect_jacobians_match(SpringForceField(skeleton), x, v);
}

TEST(ForceJacobians, SphereContactPenalty) {
  const auto mesh = icosphere(2, 0.05);
  const SpringNetwork network = build_single_layer(mesh.vertices, mesh.triangles);
  std::vector<int> all(network.num_nodes());
  for (int i = 0; i < network.num_nodes(); ++i)
    all[i] = i;
  // Tool centred above the north pole, 1 cm deep: a patch of nodes is inside.
  const SphereContactForceField contact(network.num_nodes(), all,
                                        SphereTool{{0.0, 0.0, 0.05 + 0.01}, 0.02}, 500.0);
  const Eigen::VectorXd x = flatten(network.rest_positions);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  contact.add_force(x, Eigen::VectorXd::Zero(x.size()), f);
  ASSERT_GT(f.norm(), 0.0);
  expect_jacobians_match(contact, x, Eigen::VectorXd::Zero(x.size()));
}

TEST(ForceJacobians, WholeModelWithGravityLoadsAndContact) {
  const auto mesh = icosphere(1, 0.05);
  ThreeTierOptions options;
  options.material = damped_material();
  MassSpringModel model(build_three_tier(mesh.vertices, mesh.triangles, options));
  model.set_gravity({0.0, 0.0, -9.81});
  model.set_external_force(3, {0.01, 0.0, 0.0});
  ToolIndentation indent;
  indent.contact_point = {0.0, 0.0, 0.05};
  indent.inward_direction = {0.0, 0.0, -1.0};
  indent.radius = 0.02;
  indent.depth = 0.005;
  activate_sphere_contact(model, indent);
  const Eigen::VectorXd x = perturbed(model.rest_state(), 0.001, 9);
  const Eigen::VectorXd v = perturbed(Eigen::VectorXd::Zero(x.size()), 0.1, 10);
  const auto errors = check_force_jacobians(model, x, v, 1e-7);
  EXPECT_LE(errors.dfdx_matrix, 1e-6);
  EXPECT_LE(errors.dfdx_product, 1e-6);
  EXPECT_LE(errors.dfdv_matrix, 1e-6);
  EXPECT_LE(errors.dfdv_product, 1e-6);
  // The gravity potential is large against the elastic energy here; FD round-off limits this one.
  EXPECT_LE(errors.energy_gradient, 1e-5);
}

TEST(SpringForces, InternalForcesSumToZero) {
  const auto mesh = icosphere(2, 0.05);
  ThreeTierOptions options;
  options.material.spring_damping = 0.2;
  const SpringNetwork network = build_three_tier(mesh.vertices, mesh.triangles, options);
  const SpringForceField springs(network);
  const Eigen::VectorXd x = perturbed(flatten(network.rest_positions), 0.004, 11);
  const Eigen::VectorXd v = perturbed(Eigen::VectorXd::Zero(x.size()), 0.5, 12);
  const Eigen::MatrixX3d f = unflatten(springs.force(x, v));
  const Eigen::RowVector3d total = f.colwise().sum();
  EXPECT_LE(total.norm(), 1e-12 * f.rowwise().norm().sum());
  EXPECT_GT(f.norm(), 0.0);
  // No force and no energy at rest.
  EXPECT_LE(springs.force(flatten(network.rest_positions), Eigen::VectorXd::Zero(x.size())).norm(),
            1e-12);
  EXPECT_LE(springs.potential_energy(flatten(network.rest_positions)), 1e-25);
}

TEST(SpringForces, DefiniteLinearisationIsNegativeSemidefinite) {
  const auto mesh = icosphere(1, 0.05);
  const SpringNetwork network = build_three_tier(mesh.vertices, mesh.triangles);
  const SpringForceField springs(network);
  const Eigen::VectorXd x =
      perturbed(flatten(network.rest_positions), 0.2 * network.rest_length.mean(), 13);
  const Eigen::VectorXd v = Eigen::VectorXd::Zero(x.size());
  const Eigen::MatrixXd exact = springs.dfdx(x, v, Linearisation::exact);
  const Eigen::MatrixXd definite = springs.dfdx(x, v, Linearisation::definite);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> exact_eigen(exact), definite_eigen(definite);
  EXPECT_GT(exact_eigen.eigenvalues().maxCoeff(), 1e-6);  // compressed springs: indefinite
  EXPECT_LE(definite_eigen.eigenvalues().maxCoeff(),
            1e-9 * definite_eigen.eigenvalues().cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace msfem::massspring
