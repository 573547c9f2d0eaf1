// Volume preservation: its Jacobians and energy against finite differences, the prism split against
// the closed-form shell volume, and the bulk response it adds against λ(E, ν) − λ(E, 1/4).

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numeric>
#include <random>

#include "force_jacobian_check.hpp"
#include "icosphere.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/fast_implicit_stepper.hpp"
#include "msfem/massspring/fast_stepper.hpp"
#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/modal_damping.hpp"
#include "msfem/massspring/topology_builders.hpp"
#include "msfem/massspring/volume_force_field.hpp"

namespace msfem::massspring {
namespace {

using testing::check_force_jacobians;
using testing::icosphere;
using testing::perturbed;

SpringNetwork three_tier_sphere(int level) {
  const auto mesh = icosphere(level, 0.05);
  return build_three_tier(mesh.vertices, mesh.triangles, ThreeTierOptions{});
}

// Volume preservation on the shell prisms of a three-tier network.
VolumeForceField shell_prisms(const SpringNetwork& network, double modulus) {
  const int nv = static_cast<int>(network.surface_nodes.size());
  return VolumeForceField(
      network.num_nodes(),
      tier_prisms(network.rest_positions, network.surface_triangles, nv, 3, modulus));
}

// `steps` backward-Euler steps of h from `start`: the generic integrator solved tightly, or the
// fast implicit stepper on `threads` threads to the same tolerance.
State backward_euler(const MassSpringModel& model, const State& start, double h, int steps) {
  State state = start;
  Integrator integrator(IntegratorKind::implicit_euler, {1e-13, 5000});
  for (int n = 0; n < steps; ++n)
    integrator.step(model, state, h);
  return state;
}
State fast_backward_euler(const MassSpringModel& model, const State& start, double h, int steps,
                          int threads) {
  FastImplicitStepper stepper(model, FastImplicitOptions{threads, true, 1e-13, 5000});
  stepper.set_state(start);
  for (int n = 0; n < steps; ++n)
    stepper.step(h);
  return stepper.state();
}

TEST(VolumeForceField, JacobiansAndEnergyMatchFiniteDifferences) {
  const SpringNetwork network = three_tier_sphere(1);
  const VolumeForceField volume = shell_prisms(network, 8000.0);
  // Perturbed by a fifth of the 2.5 cm shell: every element away from its rest volume.
  const Eigen::VectorXd x = perturbed(flatten(network.rest_positions), 0.004, 3);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  volume.add_force(x, Eigen::VectorXd::Zero(x.size()), f);
  ASSERT_GT(f.norm(), 0.0);
  const auto errors = check_force_jacobians(volume, x, Eigen::VectorXd::Zero(x.size()), 1e-7);
  EXPECT_LE(errors.dfdx_matrix, 1e-6);
  EXPECT_LE(errors.dfdx_product, 1e-6);
  EXPECT_LE(errors.energy_gradient, 1e-6);
  // Internal: the forces sum to zero and exert no net moment (V is invariant under rigid motion).
  Eigen::Vector3d total = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
  for (int i = 0; i < network.num_nodes(); ++i) {
    total += f.segment<3>(3 * i);
    moment += x.segment<3>(3 * i).cross(f.segment<3>(3 * i));
  }
  EXPECT_LE(total.norm(), 1e-12 * f.norm());
  EXPECT_LE(moment.norm(), 1e-12 * f.norm() * 0.05);
}

// The kept tangent (each element's gradient and volume stored once) multiplies, gives the diagonal
// blocks and the force, as the definite calls that recompute them, in one part and shared by three,
// and follows the state it was made with when set again.
void expect_kept_tangent_as_recomputed(const VolumeForceField& volume, Eigen::VectorXd x) {
  const Eigen::Index n = x.size();
  const Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd dx = perturbed(Eigen::VectorXd::Zero(n), 0.001, 5);
  const Eigen::VectorXd dx2 = perturbed(Eigen::VectorXd::Zero(n), 0.001, 9);
  const auto tangent = volume.tangent(x, v, Linearisation::definite);
  const auto close = [](const Eigen::VectorXd& got, const Eigen::VectorXd& want) {
    return (got - want).norm() <= 1e-12 * want.norm() && want.norm() > 0.0;
  };
  for (int round = 0; round < 2; ++round) {
    Eigen::VectorXd expected = Eigen::VectorXd::Zero(n), expected2 = expected, force = expected;
    volume.add_dfdx_product(x, v, dx, expected, Linearisation::definite);
    volume.add_dfdx_product(x, v, dx2, expected2, Linearisation::definite);
    volume.add_force(x, v, force);
    for (const int parts : {1, 3}) {
      Eigen::VectorXd product = Eigen::VectorXd::Zero(n), pair1 = product, pair2 = product,
                      kept_force = product;
      for (int part = 0; part < parts; ++part) {
        tangent->set_part(part, parts);
        tangent->add_product_part(dx, product, part, parts);
        tangent->add_product_pair_part(dx, pair1, dx2, pair2, part, parts);
        EXPECT_TRUE(tangent->add_force_part(kept_force, part, parts));
      }
      EXPECT_TRUE(close(product, expected)) << parts << " " << round;
      EXPECT_TRUE(close(pair1, expected)) << parts << " " << round;
      EXPECT_TRUE(close(pair2, expected2)) << parts << " " << round;
      EXPECT_TRUE(close(kept_force, force)) << parts << " " << round;
      const int nodes = static_cast<int>(n / 3);
      std::vector<Eigen::Matrix3d> blocks(nodes, Eigen::Matrix3d::Zero()), recomputed = blocks;
      for (int part = 0; part < parts; ++part)
        tangent->add_diagonal_blocks_part(2.0, 3.0, blocks, part, parts);
      volume.add_diagonal_blocks(x, v, 2.0, 3.0, recomputed, Linearisation::definite);
      double worst = 0.0, largest = 0.0;
      for (int i = 0; i < nodes; ++i) {
        worst = std::max(worst, (blocks[i] - recomputed[i]).norm());
        largest = std::max(largest, recomputed[i].norm());
      }
      ASSERT_GT(largest, 0.0);
      EXPECT_LE(worst, 1e-12 * largest) << parts << " " << round;
    }
    x = perturbed(x, 0.002, 7);  // the next round's state, read through the same tangent
  }
}

TEST(VolumeForceField, KeptTangentMultipliesAsTheRecomputedProduct) {
  const SpringNetwork network = three_tier_sphere(1);
  expect_kept_tangent_as_recomputed(shell_prisms(network, 8000.0),
                                    perturbed(flatten(network.rest_positions), 0.004, 3));
  // Lone tetrahedra (tet_edges' elements, which take their own path): a cube's six, around its
  // diagonal, with a seventh node only springs would hold.
  Eigen::MatrixX3d p(9, 3);
  p << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1, 2, 2, 2;
  p *= 0.01;
  Eigen::MatrixX4i tets(6, 4);
  tets << 0, 1, 3, 7, 0, 3, 2, 7, 0, 2, 6, 7, 0, 6, 4, 7, 0, 4, 5, 7, 0, 5, 1, 7;
  const VolumeElements elements = tetrahedron_elements(p, tets, 5000.0);
  for (int t = 0; t < 6; ++t)
    ASSERT_NEAR(std::abs(elements.rest_volume[t]), 1e-6 / 6.0, 1e-18) << t;
  expect_kept_tangent_as_recomputed(VolumeForceField(9, elements),
                                    perturbed(flatten(p), 0.002, 11));
}

TEST(VolumeForceField, PrismsRespondAlikeWhicheverCornerTheirTrianglesStartAt) {
  // Rotating each triangle's vertex order must not change the element's volume away from rest
  // (one 3-tetrahedron split alone does: its diagonals depend on the order).
  const SpringNetwork network = three_tier_sphere(1);
  const int nv = static_cast<int>(network.surface_nodes.size());
  Eigen::MatrixX3i rotated = network.surface_triangles;
  for (Eigen::Index f = 0; f < rotated.rows(); ++f)
    rotated.row(f) << network.surface_triangles(f, 1), network.surface_triangles(f, 2),
        network.surface_triangles(f, 0);
  const VolumeForceField a(network.num_nodes(), tier_prisms(network.rest_positions,
                                                            network.surface_triangles, nv, 3, 1.0));
  const VolumeForceField b(network.num_nodes(),
                           tier_prisms(network.rest_positions, rotated, nv, 3, 1.0));
  const Eigen::VectorXd x = perturbed(flatten(network.rest_positions), 0.004, 11);
  for (int e = 0; e < a.elements().num_elements(); ++e)
    EXPECT_NEAR(a.volume(x, e), b.volume(x, e), 1e-12 * std::abs(a.volume(x, e))) << e;
}

TEST(VolumeForceField, TetrahedronElementsJacobiansMatchFiniteDifferences) {
  // Two positively oriented tetrahedra sharing the face 1 2 3.
  Eigen::MatrixX3d p(5, 3);
  p << 0, 0, 0, 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01, 0.01, 0.01, 0.01;
  Eigen::MatrixX4i tets(2, 4);
  tets << 0, 1, 2, 3, 1, 2, 3, 4;
  const VolumeElements elements = tetrahedron_elements(p, tets, 5000.0);
  EXPECT_NEAR(elements.rest_volume[0], 1e-6 / 6.0, 1e-18);
  EXPECT_NEAR(elements.rest_volume[1], 2e-6 / 6.0, 1e-18);
  const VolumeForceField volume(5, elements);
  const Eigen::VectorXd x = perturbed(flatten(p), 0.002, 5);
  const auto errors = check_force_jacobians(volume, x, Eigen::VectorXd::Zero(x.size()), 1e-8);
  EXPECT_LE(errors.dfdx_matrix, 1e-6);
  EXPECT_LE(errors.dfdx_product, 1e-6);
  EXPECT_LE(errors.energy_gradient, 1e-6);
}

// Elements of two shapes, neither filling its last lane group (the force pass groups elements of
// one shape eight to a vector): prisms of the shell and single tetrahedra in the first of them.
TEST(VolumeForceField, MixedShapesInPartialLaneGroupsMatchFiniteDifferences) {
  const SpringNetwork network = three_tier_sphere(1);
  const int nv = static_cast<int>(network.surface_nodes.size());
  VolumeElements mixed =
      tier_prisms(network.rest_positions, network.surface_triangles, nv, 2, 8000.0);
  const int prisms = 77;  // of 80: 9 groups, the last with 5 lanes
  const int prism_tets = mixed.tet_start[prisms];
  mixed.tet_start.resize(prisms + 1);
  Eigen::MatrixX4i tets(prism_tets + 11, 4);
  Eigen::VectorXd weights(tets.rows());
  tets.topRows(prism_tets) = mixed.tets.topRows(prism_tets);
  weights.head(prism_tets) = mixed.tet_weight.head(prism_tets);
  for (int k = 0; k < 11; ++k) {  // the first tetrahedron of each of 11 prisms, weight 1
    tets.row(prism_tets + k) = mixed.tets.row(mixed.tet_start[k]);
    weights[prism_tets + k] = 1.0;
    mixed.tet_start.push_back(prism_tets + k + 1);
  }
  mixed.tets = tets;
  mixed.tet_weight = weights;
  const Eigen::VectorXd x0 = flatten(network.rest_positions);
  mixed.rest_volume.conservativeResize(prisms + 11);
  mixed.modulus = Eigen::VectorXd::LinSpaced(prisms + 11, 2000.0, 9000.0);
  for (int k = 0; k < 11; ++k) {
    const Eigen::Vector3d a = network.rest_positions.row(tets(prism_tets + k, 0)),
                          b = network.rest_positions.row(tets(prism_tets + k, 1)),
                          c = network.rest_positions.row(tets(prism_tets + k, 2)),
                          d = network.rest_positions.row(tets(prism_tets + k, 3));
    mixed.rest_volume[prisms + k] = (b - a).dot((c - a).cross(d - a)) / 6.0;
  }
  const VolumeForceField volume(network.num_nodes(), mixed);
  const Eigen::VectorXd x = perturbed(x0, 0.004, 17);
  const auto errors = check_force_jacobians(volume, x, Eigen::VectorXd::Zero(x.size()), 1e-7);
  EXPECT_LE(errors.dfdx_matrix, 1e-6);
  EXPECT_LE(errors.dfdx_product, 1e-6);
  EXPECT_LE(errors.energy_gradient, 1e-6);
  // Three parts sum to the whole force; every call a solver makes, the kept tangent's rows
  // among them (its elements grouped anew), answers as the whole calls.
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size()), parts = f;
  volume.add_force(x, Eigen::VectorXd::Zero(x.size()), f);
  for (int part = 0; part < 3; ++part)
    volume.add_force_part(x, Eigen::VectorXd::Zero(x.size()), parts, part, 3);
  EXPECT_LE((parts - f).norm(), 1e-13 * f.norm());
  const auto calls = testing::check_field_calls(volume, x, Eigen::VectorXd::Zero(x.size()));
  EXPECT_LT(calls.worst(), 1e-12) << "rows " << calls.tangent_rows << ", start "
                                  << calls.tangent_start << ", start rows "
                                  << calls.tangent_start_rows;
}

TEST(VolumeForceField, PrismsFillTheShellsBetweenTheTiers) {
  // The icosphere's tiers are scaled copies, so the prisms between tiers s1 and s2 fill exactly
  // the enclosed polyhedra's volume difference, (1/s1³ − 1/s2³) V_outer.
  const auto mesh = icosphere(2, 0.05);
  const SpringNetwork network = build_three_tier(mesh.vertices, mesh.triangles, ThreeTierOptions{});
  const int nv = static_cast<int>(mesh.vertices.rows());
  const VolumeElements prisms = tier_prisms(network.rest_positions, mesh.triangles, nv, 3, 1.0);
  ASSERT_EQ(prisms.num_elements(), 2 * mesh.triangles.rows());
  double outer = 0.0;
  for (Eigen::Index f = 0; f < mesh.triangles.rows(); ++f) {
    const Eigen::Vector3d a = mesh.vertices.row(mesh.triangles(f, 0)).transpose();
    const Eigen::Vector3d b = mesh.vertices.row(mesh.triangles(f, 1)).transpose();
    const Eigen::Vector3d c = mesh.vertices.row(mesh.triangles(f, 2)).transpose();
    outer += a.dot(b.cross(c)) / 6.0;
  }
  const Eigen::Index half = mesh.triangles.rows();
  const double shell12 = prisms.rest_volume.head(half).sum();
  const double shell23 = prisms.rest_volume.tail(half).sum();
  // Outward triangles over inward-pointing prisms: every prism volume has one sign.
  EXPECT_TRUE((prisms.rest_volume.array() < 0).all() || (prisms.rest_volume.array() > 0).all());
  EXPECT_NEAR(std::abs(shell12), outer * (1 - 1 / std::pow(1.2, 3)), 1e-12 * outer);
  EXPECT_NEAR(std::abs(shell23), outer * (1 / std::pow(1.2, 3) - 1 / 8.0), 1e-12 * outer);
}

TEST(VolumeForceField, UniformDilatationCostsTheBulkEnergyOfTheModulus) {
  // Scaling every node by (1 + ε) changes each volume by (1 + ε)³ − 1: U = ½ κ V⁰ ((1+ε)³ − 1)²,
  // the continuum's ½ κ (tr ε)² V⁰ to first order.
  const SpringNetwork network = three_tier_sphere(2);
  const int nv = static_cast<int>(network.surface_nodes.size());
  const double kappa = volume_modulus_for(3000.0, 0.45);
  const VolumeForceField volume(
      network.num_nodes(),
      tier_prisms(network.rest_positions, network.surface_triangles, nv, 3, kappa));
  const double eps = 1e-3;
  const Eigen::VectorXd x = (1 + eps) * flatten(network.rest_positions);
  const double total_rest = volume.elements().rest_volume.cwiseAbs().sum();
  const double dv = std::pow(1 + eps, 3) - 1;
  EXPECT_NEAR(volume.potential_energy(x), 0.5 * kappa * total_rest * dv * dv,
              1e-9 * 0.5 * kappa * total_rest * dv * dv);
  EXPECT_NEAR(kappa, 3000.0 * (0.45 / (1.45 * 0.1) - 0.25 / (1.25 * 0.5)), 1e-9);
  EXPECT_EQ(volume_modulus_for(3000.0, 0.25), 0.0);
  EXPECT_EQ(volume_modulus_for(3000.0, 0.2), 0.0);
}

TEST(VolumeForceField, RejectsBadElements) {
  const SpringNetwork network = three_tier_sphere(1);
  const int nv = static_cast<int>(network.surface_nodes.size());
  VolumeElements good = tier_prisms(network.rest_positions, network.surface_triangles, nv, 3, 1.0);
  VolumeElements bad_node = good;
  bad_node.tets(5, 2) = network.num_nodes();
  EXPECT_THROW(VolumeForceField(network.num_nodes(), bad_node), ModelError);
  VolumeElements bad_modulus = good;
  bad_modulus.modulus[1] = std::nan("");
  EXPECT_THROW(VolumeForceField(network.num_nodes(), bad_modulus), ModelError);
  VolumeElements bad_weight = good;
  bad_weight.tet_weight.conservativeResize(bad_weight.tet_weight.size() - 1);
  EXPECT_THROW(VolumeForceField(network.num_nodes(), bad_weight), ModelError);
  VolumeElements flat_element = good;
  flat_element.rest_volume[0] = 0.0;
  EXPECT_THROW(VolumeForceField(network.num_nodes(), flat_element), ModelError);
  MassSpringModel model(network);
  EXPECT_THROW(model.set_volume(VolumeForceField(nv, VolumeElements{})), ModelError);
}

TEST(VolumeForceField, InvertedAndFlatPrismsOfAFoldedTierAreRemoved) {
  const auto mesh = icosphere(1, 0.05);
  SpringNetwork network = build_three_tier(mesh.vertices, mesh.triangles, ThreeTierOptions{});
  const int nv = static_cast<int>(mesh.vertices.rows());
  // Fold tier 2 over triangle 0: its three tier-2 copies pushed beyond the surface invert the 1-2
  // prism there. Flatten the 2-3 prism of triangle 1: its tier-3 copies onto tier 2.
  for (int k = 0; k < 3; ++k) {
    const int a = mesh.triangles(0, k), b = mesh.triangles(1, k);
    network.rest_positions.row(nv + a) = 1.1 * network.rest_positions.row(a);
    network.rest_positions.row(2 * nv + b) = network.rest_positions.row(nv + b);
  }
  VolumeElements prisms = tier_prisms(network.rest_positions, mesh.triangles, nv, 3, 1.0);
  const int before = prisms.num_elements();
  const double inverted = prisms.rest_volume[0],
               flat = prisms.rest_volume[mesh.triangles.rows() + 1];
  EXPECT_LT(inverted * prisms.rest_volume.sum(), 0.0);
  EXPECT_NEAR(flat, 0.0, 1e-15);
  const int removed = remove_degenerate_elements(prisms, network.rest_positions, 1e-3);
  EXPECT_GE(removed, 2);
  EXPECT_EQ(prisms.num_elements(), before - removed);
  EXPECT_LT(removed, before / 4);
  const double sign = prisms.rest_volume[0] > 0 ? 1.0 : -1.0;
  for (int e = 0; e < prisms.num_elements(); ++e)
    EXPECT_GT(sign * prisms.rest_volume[e], 0.0) << e;
  // What is left is still a valid field, and a second pass removes nothing.
  EXPECT_NO_THROW(VolumeForceField(network.num_nodes(), prisms));
  EXPECT_EQ(remove_degenerate_elements(prisms, network.rest_positions, 1e-3), 0);
}

TEST(VolumeForceField, SmallButWellShapedTetrahedraOfAGradedMeshAreKept) {
  // The same corner tetrahedron at 1 cm and at 10 µm, and a sliver (apex 1e-5 of its size off the
  // base plane): only the sliver is flat.
  Eigen::MatrixX3d p(12, 3);
  p << 0, 0, 0, 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01,  //
      0, 0, 0, 1e-5, 0, 0, 0, 1e-5, 0, 0, 0, 1e-5,   //
      0, 0, 0, 0.01, 0, 0, 0, 0.01, 0, 0.005, 0.005, 1e-7;
  for (int i = 4; i < 8; ++i)
    p.row(i) += Eigen::RowVector3d(0.1, 0, 0);
  for (int i = 8; i < 12; ++i)
    p.row(i) += Eigen::RowVector3d(0.2, 0, 0);
  Eigen::MatrixX4i tets(3, 4);
  tets << 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11;
  VolumeElements elements = tetrahedron_elements(p, tets, 1.0);
  EXPECT_EQ(remove_degenerate_elements(elements, p, 1e-3), 1);
  ASSERT_EQ(elements.num_elements(), 2);
  EXPECT_NEAR(elements.rest_volume[1], 1e-15 / 6.0, 1e-20);  // the small one is still there
}

// The fast steppers step the volume elements as the generic integrators do (a squeezed start, so
// that they push): symplectic Euler, explicit Euler and RK4 on the explicit kernels, backward Euler
// on the implicit ones with the elements' definite Jacobian in its products and preconditioner.
TEST(VolumeForceField, FastSteppersStepTheVolumeAsTheGenericIntegrators) {
  const SpringNetwork network = three_tier_sphere(1);
  const int nv = static_cast<int>(network.surface_nodes.size());
  MassSpringModel model(network);
  for (int node = 2 * nv; node < network.num_nodes(); ++node)
    model.fix_node(node);
  model.set_volume(VolumeForceField(
      network.num_nodes(),
      tier_prisms(network.rest_positions, network.surface_triangles, nv, 3, 1000.0)));
  State start = initial_state(model);
  for (int node = 0; node < nv; ++node)
    start.x.segment<3>(3 * node) *= 0.97;  // the outer shell squeezed: the prisms lose volume
  State generic = start;
  Integrator integrator(IntegratorKind::symplectic_euler);
  FastExplicitStepper fast(model, FastStepperOptions{2, false, true, true});
  fast.set_state(start);
  const double dt = 1e-5;
  for (int n = 0; n < 200; ++n)
    integrator.step(model, generic, dt);
  fast.step(dt, 200);
  const double travel = (generic.x - start.x).norm();
  ASSERT_GT(travel, 1e-7);
  EXPECT_LT((fast.state().x - generic.x).norm(), 1e-9 * travel);
  MassSpringModel springs_only(network);
  for (int node = 2 * nv; node < network.num_nodes(); ++node)
    springs_only.fix_node(node);
  FastExplicitStepper blind(springs_only, FastStepperOptions{2, false, true, true});
  blind.set_state(start);
  blind.step(dt, 200);
  EXPECT_GT((blind.state().x - generic.x).norm(), 1e-3 * travel);  // the volume force mattered

  // Backward Euler at a step 100x the explicit one, solved tightly: the same steps on one and two
  // threads, and in float to its precision; the volume's stiffness changed the steps.
  const double h = 1e-3;
  const State backward = backward_euler(model, start, h, 20);
  const double backward_travel = (backward.x - start.x).norm();
  ASSERT_GT(backward_travel, 1e-6);
  for (const int threads : {1, 2})
    EXPECT_LT((fast_backward_euler(model, start, h, 20, threads).x - backward.x).norm(),
              1e-8 * backward_travel)
        << threads;
  FastImplicitOptions single{2, true, 1e-6, 5000};
  single.single_precision = true;
  FastImplicitStepper implicit_float(model, single);
  implicit_float.set_state(start);
  FastImplicitStepper implicit_blind(springs_only, FastImplicitOptions{2, true, 1e-13, 5000});
  implicit_blind.set_state(start);
  for (int n = 0; n < 20; ++n) {
    implicit_float.step(h);
    implicit_blind.step(h);
  }
  EXPECT_LT((implicit_float.state().x - backward.x).norm(), 1e-4 * backward_travel);
  EXPECT_GT((implicit_blind.state().x - backward.x).norm(), 1e-2 * backward_travel);

  // Explicit Euler on the same kernels: the field's impulse reaches v, and x only a step later.
  State euler = start;
  Integrator euler_integrator(IntegratorKind::explicit_euler);
  for (int n = 0; n < 200; ++n)
    euler_integrator.step(model, euler, dt);
  FastStepperOptions options{2, false, true, true};
  options.integrator = IntegratorKind::explicit_euler;
  FastExplicitStepper fast_euler(model, options);
  fast_euler.set_state(start);
  fast_euler.step(dt, 200);
  EXPECT_LT((fast_euler.state().x - euler.x).norm(), 1e-9 * travel);
  EXPECT_LT((fast_euler.state().v - euler.v).norm(), 1e-9 * euler.v.norm());

  // RK4: the volume force at each stage's state, its elements shared by the two threads.
  State rk4 = start;
  Integrator rk4_integrator(IntegratorKind::rk4);
  for (int n = 0; n < 200; ++n)
    rk4_integrator.step(model, rk4, dt);
  options.integrator = IntegratorKind::rk4;
  FastExplicitStepper fast_rk4(model, options);
  fast_rk4.set_state(start);
  fast_rk4.step(dt, 200);
  EXPECT_LT((fast_rk4.state().x - rk4.x).norm(), 1e-9 * travel);
  EXPECT_LT((fast_rk4.state().v - rk4.v).norm(), 1e-9 * rk4.v.norm());
  EXPECT_GT((rk4.x - generic.x).norm(), 1e-4 * travel);  // not symplectic Euler's states
}

// tet_edges with volume preservation, the accurate model, as the fast implicit stepper runs it:
// its elements' dot products and row sums (lone tetrahedra, many at a node, the last lane group
// partly filled) against the generic backward Euler, on one and two threads.
TEST(VolumeForceField, FastImplicitStepsTetrahedraAsTheGenericIntegrator) {
  // A 3 × 3 × 3 block of 1 cm cubes, six tetrahedra around each one's diagonal: 64 nodes, 162
  // elements, up to 24 at a node.
  constexpr int n = 4;
  Eigen::MatrixX3d p(n * n * n, 3);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        p.row(x + n * (y + n * z)) = 0.01 * Eigen::RowVector3d(x, y, z);
  const int around_diagonal[6][4] = {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7},
                                     {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}};
  Eigen::MatrixX4i tets(6 * (n - 1) * (n - 1) * (n - 1), 4);
  int t = 0;
  for (int z = 0; z + 1 < n; ++z)
    for (int y = 0; y + 1 < n; ++y)
      for (int x = 0; x + 1 < n; ++x)
        for (const auto& corners : around_diagonal) {
          for (int c = 0; c < 4; ++c) {
            const int k = corners[c];  // a cube corner: bit 0 x, bit 1 y, bit 2 z
            tets(t, c) = (x + (k & 1)) + n * ((y + (k >> 1 & 1)) + n * (z + (k >> 2 & 1)));
          }
          ++t;
        }
  const SpringNetwork network = build_tet_edges(p, tets);
  MassSpringModel model(network);
  for (int node = 0; node < n * n; ++node)
    model.fix_node(node);  // the bottom face
  model.set_volume(VolumeForceField(network.num_nodes(), tetrahedron_elements(p, tets, 20000.0)));
  State start = initial_state(model);
  for (int node = n * n * (n - 1); node < n * n * n; ++node)
    start.x[3 * node + 2] -= 0.002;  // the top face pressed down 2 mm

  const double h = 1e-3;
  const State backward = backward_euler(model, start, h, 20);
  const double travel = (backward.x - start.x).norm();
  ASSERT_GT(travel, 1e-5);
  for (const int threads : {1, 2})
    EXPECT_LT((fast_backward_euler(model, start, h, 20, threads).x - backward.x).norm(),
              1e-8 * travel)
        << threads;
  MassSpringModel springs_only(network);
  for (int node = 0; node < n * n; ++node)
    springs_only.fix_node(node);
  const State blind = fast_backward_euler(springs_only, start, h, 20, 2);
  EXPECT_GT((blind.x - backward.x).norm(), 1e-2 * travel);  // the volume mattered
}

// Where CG converges slowly — volume preservation on the prisms of a small sphere with millimetre
// springs, stiff against its masses at a 1 ms step, as on the brain — the trend start takes
// fewer iterations than the last step's Δv, and changes no solution beyond the solve's tolerance,
// on one thread or two.
TEST(VolumeForceField, TrendStartCutsSlowSolvesAndKeepsTheirSolution) {
  const auto mesh = icosphere(3, 0.005);
  ThreeTierOptions options;
  options.material.youngs_modulus = 3000.0;
  options.material.density = 1040.0;
  SpringNetwork network = build_three_tier(mesh.vertices, mesh.triangles, options);
  network.damping = damping_for_ratio(network, 0.5);
  const int nv = static_cast<int>(network.surface_nodes.size());
  MassSpringModel model(network);
  for (int node = 2 * nv; node < network.num_nodes(); ++node)
    model.fix_node(node);
  model.set_volume(shell_prisms(network, volume_modulus_for(3000.0, 0.45)));
  State start = initial_state(model);
  start.x = perturbed(start.x, 1e-3 * network.rest_length.mean(), 2007);  // every mode excited
  model.enforce_constraints(start.x, start.v);

  // 200 steps, the state set again after 100 and the step halved after 150 (each starts the trend
  // anew); the iterations of steps 50 to 200, and the last state.
  const auto run = [&](bool trend, int threads, double tolerance, std::vector<int>* iterations) {
    FastImplicitOptions o{threads, true, tolerance, 5000};
    o.adaptive_threads = false;
    o.trend_start = trend;
    FastImplicitStepper stepper(model, o);
    stepper.set_state(start);
    for (int n = 0; n < 200; ++n) {
      if (n == 100) stepper.set_state(stepper.state());
      stepper.step(n < 150 ? 1e-3 : 5e-4);
      if (iterations && n >= 50) iterations->push_back(stepper.last_cg_iterations());
    }
    return stepper.state();
  };
  const auto total = [](const std::vector<int>& v) {
    return std::accumulate(v.begin(), v.end(), 0);
  };
  std::vector<int> plain, trend;
  run(false, 2, 1e-2, &plain);
  run(true, 2, 1e-2, &trend);
  EXPECT_GE(total(plain), 6 * static_cast<int>(plain.size()));  // the slow regime
  EXPECT_LT(total(trend), 0.85 * total(plain));

  const State tight = run(false, 2, 1e-10, nullptr);
  const double travel = (tight.x - start.x).norm();
  ASSERT_GT(travel, 1e-5);
  for (const int threads : {1, 2})
    EXPECT_LT((run(true, threads, 1e-10, nullptr).x - tight.x).norm(), 1e-8 * travel) << threads;
}

}  // namespace
}  // namespace msfem::massspring
