// The sphere against the surface's triangles: Jacobians and energy by finite differences (alone
// and in the composed model of springs, volume elements and contact), the fast implicit stepper
// stepping that model as the generic backward Euler, the closed-form force of a tool pressed on a
// triangle's centre, and the broad phase.

#include <gtest/gtest.h>

#include <cmath>

#include "force_jacobian_check.hpp"
#include "icosphere.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/fast_implicit_stepper.hpp"
#include "msfem/massspring/integrators.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/surface_contact.hpp"
#include "msfem/massspring/topology_builders.hpp"
#include "msfem/massspring/volume_force_field.hpp"

namespace msfem::massspring {
namespace {

using testing::check_force_jacobians;
using testing::icosphere;
using testing::perturbed;
using testing::TriangleMesh;

TEST(SurfaceContact, JacobiansAndEnergyMatchFiniteDifferences) {
  const auto mesh = icosphere(2, 0.05);
  // A 4 mm tool pressed 1 mm into the sphere between nodes (edges ~ 15 mm).
  const SurfaceContactForceField contact(
      mesh.vertices, mesh.triangles, SphereTool{{0.003, 0.002, 0.05 + 0.004 - 0.001}, 0.004}, 2e6);
  const Eigen::VectorXd x = perturbed(flatten(mesh.vertices), 2e-4, 21);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  contact.add_force(x, Eigen::VectorXd::Zero(x.size()), f);
  ASSERT_GT(f.norm(), 0.0);
  const auto errors = check_force_jacobians(contact, x, Eigen::VectorXd::Zero(x.size()), 1e-8);
  EXPECT_LE(errors.dfdx_matrix, 1e-5);
  EXPECT_LE(errors.dfdx_product, 1e-5);
  EXPECT_LE(errors.energy_gradient, 1e-5);
}

// The level-1 sphere's three tiers, damped, with volume preservation on their shells and gravity:
// every kind of force beside the contact.
MassSpringModel composed_sphere(const TriangleMesh& mesh) {
  ThreeTierOptions options;
  options.material.youngs_modulus = 3000.0;
  options.material.spring_damping = 0.05;
  MassSpringModel model(build_three_tier(mesh.vertices, mesh.triangles, options));
  const int nv = int(mesh.vertices.rows());
  model.set_volume(VolumeForceField(
      model.num_nodes(),
      tier_prisms(model.network().rest_positions, model.network().surface_triangles, nv, 3, 8e3)));
  model.set_gravity({0.0, 0.0, -9.81});
  return model;
}

TEST(SurfaceContact, ComposedModelOfSpringsVolumeAndContactMatchesFiniteDifferences) {
  const auto mesh = icosphere(1, 0.05);
  MassSpringModel model = composed_sphere(mesh);
  ToolIndentation indent;
  indent.contact_point = {0.0, 0.0, 0.05};
  indent.radius = 0.01;
  indent.depth = 0.004;
  activate_surface_contact(model, indent);
  const Eigen::VectorXd x = perturbed(model.rest_state(), 0.001, 22);
  const Eigen::VectorXd v = perturbed(Eigen::VectorXd::Zero(x.size()), 0.1, 23);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  model.contact()->add_force(x, v, f);
  ASSERT_GT(f.norm(), 0.0);
  const auto errors = check_force_jacobians(model, x, v, 1e-7);
  EXPECT_LE(errors.dfdx_matrix, 1e-6);
  EXPECT_LE(errors.dfdx_product, 1e-6);
  EXPECT_LE(errors.dfdv_matrix, 1e-6);
  EXPECT_LE(errors.dfdv_product, 1e-6);
  EXPECT_LE(errors.energy_gradient, 1e-5);
}

// The fast implicit stepper carries the contact and the volume in its CG products (by rows: each
// thread its own nodes' whole rows) and takes the generic backward Euler's steps, on one and two
// threads. The tool presses a face between its nodes, so that no node enters it: the generic
// integrator projects nodes out of the tool after each step, which the fast steppers do not.
TEST(SurfaceContact, FastImplicitStepsTheContactAsTheGenericBackwardEuler) {
  const auto mesh = icosphere(1, 0.05);
  MassSpringModel model = composed_sphere(mesh);
  const Eigen::Vector3d centroid =
      (mesh.vertices.row(mesh.triangles(0, 0)) + mesh.vertices.row(mesh.triangles(0, 1)) +
       mesh.vertices.row(mesh.triangles(0, 2)))
          .transpose() /
      3.0;
  ToolIndentation indent;
  indent.contact_point = centroid;
  indent.inward_direction = -centroid.normalized();
  indent.radius = 0.004;
  indent.depth = 0.001;
  activate_surface_contact(model, indent);
  const State start{model.rest_state(), Eigen::VectorXd::Zero(model.num_dofs()), 0.0};
  Eigen::VectorXd f = Eigen::VectorXd::Zero(model.num_dofs());
  model.contact()->add_force(start.x, start.v, f);
  ASSERT_GT(f.norm(), 0.0);
  State backward = start;
  Integrator generic(IntegratorKind::implicit_euler, {1e-13, 5000});
  const SphereTool& tool = model.contact()->tool();
  for (int n = 0; n < 20; ++n) {
    generic.step(model, backward, 1e-3);
    for (int i : model.contact()->nodes())
      ASSERT_GT((backward.x.segment<3>(3 * i) - tool.center).norm(), tool.radius) << n << " " << i;
  }
  const double travel = (backward.x - start.x).norm();
  ASSERT_GT(travel, 1e-6);
  for (const int threads : {1, 2}) {
    FastImplicitStepper fast(model, FastImplicitOptions{threads, true, 1e-13, 5000});
    fast.set_state(start);
    for (int n = 0; n < 20; ++n)
      fast.step(1e-3);
    EXPECT_LT((fast.state().x - backward.x).norm(), 1e-8 * travel) << threads;
    EXPECT_LT((fast.state().v - backward.v).norm(), 1e-8 * backward.v.norm()) << threads;
  }
}

/// An equilateral triangle in z = 0 (circumradius 3r), closed into a flat tetrahedron-free
/// "surface" of one triangle; nodes far outside the tool.
struct Triangle {
  Eigen::MatrixX3d vertices{3, 3};
  Eigen::MatrixX3i triangles{1, 3};
  Triangle(double circumradius) {
    for (int k = 0; k < 3; ++k) {
      const double angle = 2 * M_PI * k / 3;
      vertices.row(k) << circumradius * std::cos(angle), circumradius * std::sin(angle), 0.0;
    }
    triangles << 0, 1, 2;
  }
};

// A tool pressed on the centre of a triangle touches none of its nodes; each node hangs on a
// vertical spring k_s. By symmetry the triangle sinks rigidly by u, the tool's penetration is
// δ = d - u at height h = r - δ above the plane, and the pressure κ (r - ρ) integrates to
// F_z = π κ h δ²; equilibrium 3 k_s u = F_z fixes u. The three springs carry exactly that force.
TEST(SurfaceContact, ToolOnATrianglesCentreGivesTheClosedFormForceOfItsThreeSprings) {
  const double r = 0.005, d = 0.001, kappa = 4e7, k_s = 50.0;
  const Triangle triangle(3 * r);
  const SurfaceContactForceField contact(triangle.vertices, triangle.triangles,
                                         SphereTool{{0.0, 0.0, r - d}, r}, kappa);
  const auto closed_form = [&](double u) {
    const double delta = d - u, h = r - delta;
    return M_PI * kappa * h * delta * delta;
  };
  const auto contact_force = [&](double u) {
    Eigen::VectorXd x = flatten(triangle.vertices);
    for (int k = 0; k < 3; ++k)
      x[3 * k + 2] -= u;
    Eigen::VectorXd f = Eigen::VectorXd::Zero(9);
    contact.add_force(x, Eigen::VectorXd::Zero(9), f);
    for (int k = 0; k < 3; ++k) {  // no node inside the tool, yet each is pushed alike
      EXPECT_GT((x.segment<3>(3 * k) - contact.tool().center).norm(), r);
      EXPECT_NEAR(f[3 * k + 2], f[2], 1e-9 * std::abs(f[2]));
    }
    return Eigen::Vector3d(f[0] + f[3] + f[6], f[1] + f[4] + f[7], f[2] + f[5] + f[8]);
  };
  // Bisection on the springs' balance, u in (0, d).
  double low = 0.0, high = d;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (low + high);
    (-contact_force(mid).z() > 3 * k_s * mid ? low : high) = mid;
  }
  const double u = 0.5 * (low + high);
  const Eigen::Vector3d force = contact_force(u);
  EXPECT_LT(std::hypot(force.x(), force.y()), 1e-9 * std::abs(force.z()));
  EXPECT_NEAR(-force.z(), 3 * k_s * u, 1e-6 * 3 * k_s * u);
  EXPECT_NEAR(-force.z(), closed_form(u), 0.03 * closed_form(u));
  // The same closed form at another penetration, away from the equilibrium.
  EXPECT_NEAR(-contact_force(0.2 * d).z(), closed_form(0.2 * d), 0.03 * closed_form(0.2 * d));
}

TEST(SurfaceContact, BroadPhaseFollowsTheSurfaceAsItMoves) {
  const auto mesh = icosphere(2, 0.05);
  // A tool 3 cm above the sphere touches nothing at rest ...
  const SurfaceContactForceField contact(mesh.vertices, mesh.triangles,
                                         SphereTool{{0.0, 0.0, 0.085}, 0.01}, 1e6);
  Eigen::VectorXd x = flatten(mesh.vertices);
  EXPECT_EQ(contact.potential_energy(x), 0.0);
  // ... and is found once the whole surface has moved up 3 cm.
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i)
    x[3 * i + 2] += 0.03;
  EXPECT_GT(contact.potential_energy(x), 0.0);
  EXPECT_GT(contact.contact_area(x), 0.0);
}

TEST(SurfaceContact, RefusesBadInput) {
  const auto mesh = icosphere(1, 0.05);
  EXPECT_THROW(
      SurfaceContactForceField(mesh.vertices, mesh.triangles, SphereTool{{0, 0, 0}, 0.0}, 1.0),
      ModelError);
  EXPECT_THROW(
      SurfaceContactForceField(mesh.vertices, mesh.triangles, SphereTool{{0, 0, 0}, 0.01}, -1.0),
      ModelError);
  Eigen::MatrixX3i bad = mesh.triangles;
  bad(0, 0) = int(mesh.vertices.rows());
  EXPECT_THROW(SurfaceContactForceField(mesh.vertices, bad, SphereTool{{0, 0, 0}, 0.01}, 1.0),
               ModelError);
}

}  // namespace
}  // namespace msfem::massspring
