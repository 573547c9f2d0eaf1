// A field written outside massspring (the grasper of grasper.hpp, which couples its nodes through
// their centroid and has a dashpot) works in every solver with no change to massspring: the
// static Newton solve, the linearised statics, every integrator, both fast steppers, the stability
// estimate and the modal damping fit. Every field, msfem's own and the grasper, answers the calls
// a solver makes of it as the whole calls they stand for.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "force_jacobian_check.hpp"
#include "grasper.hpp"
#include "icosphere.hpp"
#include "msfem/massspring/fast_implicit_stepper.hpp"
#include "msfem/massspring/fast_stepper.hpp"
#include "msfem/massspring/linearised_statics.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/modal_damping.hpp"
#include "msfem/massspring/stability.hpp"
#include "msfem/massspring/static_solver.hpp"
#include "msfem/massspring/surface_contact.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {
namespace {

using testing::check_field_calls;
using testing::check_force_jacobians;
using testing::Grasper;
using testing::icosphere;
using testing::perturbed;

struct Grasped {
  MassSpringModel model;
  std::shared_ptr<Grasper> grasper;  ///< the model's, moved by the test as a simulator moves it
  Eigen::Vector3d centroid;          ///< of the grasped nodes at rest
};

// The three tiers of a 5 cm sphere held within `held_radius` (their core), the five surface nodes
// nearest the +z pole grasped and pulled `pull` along z.
Grasped grasped_sphere(double k, double c, double pull, double held_radius = 0.03) {
  const auto mesh = icosphere(1, 0.05);
  MassSpringModel model(build_three_tier(mesh.vertices, mesh.triangles, ThreeTierOptions{}));
  model.set_group_damping("tier1_edges", 0.01);
  const Eigen::VectorXd rest = model.rest_state();
  for (int node = 0; node < model.num_nodes(); ++node)
    if (rest.segment<3>(3 * node).norm() < held_radius) model.fix_node(node);
  std::vector<int> surface = model.network().surface_nodes;
  std::sort(surface.begin(), surface.end(),
            [&](int a, int b) { return rest[3 * a + 2] > rest[3 * b + 2]; });
  const std::vector<int> held(surface.begin(), surface.begin() + 5);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int i : held)
    centroid += rest.segment<3>(3 * i) / 5.0;
  auto grasper = std::make_shared<Grasper>(model.num_nodes(), held,
                                           centroid + Eigen::Vector3d(0, 0, pull), k, c);
  model.add_field(grasper);
  return {std::move(model), grasper, centroid};
}

TEST(OutsideField, EveryFieldAnswersASolversCallsAsTheWholeCalls) {
  Grasped g = grasped_sphere(200.0, 0.05, 0.004);
  const MassSpringModel& model = g.model;
  const SpringNetwork& net = model.network();
  const Eigen::VectorXd x = perturbed(model.rest_state(), 0.002, 5);
  const Eigen::VectorXd v = perturbed(0 * x, 0.01, 6);
  const auto errors = check_force_jacobians(*g.grasper, x, v, 1e-7);
  EXPECT_LT(errors.dfdx_matrix, 1e-6);
  EXPECT_LT(errors.dfdx_product, 1e-6);
  EXPECT_LT(errors.dfdv_matrix, 1e-6);
  EXPECT_LT(errors.energy_gradient, 1e-6);
  const auto with_springs = check_force_jacobians(model, x, v, 1e-7);
  EXPECT_LT(with_springs.dfdx_matrix, 1e-5);
  EXPECT_LT(with_springs.dfdv_product, 1e-5);

  // msfem's own fields at the same state: a tool pressed 4 mm into the pole (nodes and surface),
  // volume preservation on the outer shell.
  const SphereTool tool{g.centroid + Eigen::Vector3d(0, 0, 0.006), 0.01};
  const SphereContactForceField nodes(model.num_nodes(), net.surface_nodes, tool, 5e4);
  const SurfaceContactForceField surface(net.rest_positions, net.surface_triangles, tool, 3e7);
  const VolumeForceField volume(model.num_nodes(),
                                tier_prisms(net.rest_positions, net.surface_triangles,
                                            static_cast<int>(net.surface_nodes.size()), 3, 500.0));
  const std::vector<std::pair<const char*, const ForceField*>> fields = {
      {"springs", &model.springs()},
      {"grasper", g.grasper.get()},
      {"node contact", &nodes},
      {"surface contact", &surface},
      {"volume", &volume}};
  for (const auto& [name, field] : fields) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
    field->add_force(x, v, f);
    ASSERT_GT(f.norm(), 0.0) << name << ": the state must load the field";
    const auto calls = check_field_calls(*field, x, v);
    EXPECT_LT(calls.worst(), 1e-12)
        << name << ": parts " << calls.force_parts << " " << calls.product_parts << ", blocks "
        << calls.diagonal_blocks << ", tangent " << calls.tangent_product << " "
        << calls.tangent_pair_product << " " << calls.tangent_blocks << " " << calls.tangent_force
        << " rows " << calls.tangent_rows << ", outside " << calls.outside_nodes;
  }
}

// Newton's equilibrium under a small pull against the model linearised at rest (one solve of
// f(rest) + J u = 0): they agree to second order in the pull, and the grasper moves its nodes.
TEST(OutsideField, StaticNewtonAndTheLinearisedSolveAgree) {
  const double pull = 1e-4;
  // The tiers below the surface held: at rest, unloaded, the inner tiers' nodes turn freely
  // about the core (a mechanism the linearised solve cannot take).
  Grasped g = grasped_sphere(400.0, 0.0, pull, 0.049);
  StaticOptions options;
  const StaticResult newton = solve_static(g.model, options);
  ASSERT_TRUE(newton.converged);
  LinearisedStatics statics(g.model, {g.model.network().stiffness});
  ASSERT_EQ(statics.num_parts(), 2);
  const auto linear = statics.solve({1.0, 1.0}, {});
  const Eigen::MatrixX3d newton_u = g.model.surface_displacement(newton.x);
  const double moved = newton_u.norm();
  ASSERT_GT(moved, 1e-3 * pull);
  EXPECT_LT((linear.surface_displacement - newton_u).norm(), 1e-2 * moved);
  // The grasped centroid is pulled toward the point, not past it.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int i : g.grasper->nodes())
    centroid += newton.x.segment<3>(3 * i) / 5.0;
  EXPECT_GT(centroid.z() - g.centroid.z(), 0.05 * pull);
  EXPECT_LT(centroid.z() - g.centroid.z(), pull);
}

// The grasp moves at t = 3 ms. Each generic integrator at a small step follows RK4 at a tenth of
// it (first order or better); each fast stepper takes its generic integrator's steps, the move
// included; without the grasper the same steps end elsewhere.
TEST(OutsideField, EveryIntegratorAndBothFastSteppersFollowAMovingGrasp) {
  Grasped g = grasped_sphere(300.0, 0.02, 0.002);
  const MassSpringModel& model = g.model;
  const Eigen::Vector3d first = g.centroid + Eigen::Vector3d(0, 0, 0.002);
  const Eigen::Vector3d second = g.centroid + Eigen::Vector3d(0.002, 0, 0);
  const State start = initial_state(model);
  const double dt = 2e-5;
  const int half = 150;
  auto generic = [&](IntegratorKind kind, double h, const MassSpringModel& m) {
    Integrator integrator(kind, {1e-13, 5000});
    State s = start;
    const int steps = static_cast<int>(std::lround(half * dt / h));
    g.grasper->move_to(first);
    for (int n = 0; n < steps; ++n)
      integrator.step(m, s, h);
    g.grasper->move_to(second);
    for (int n = 0; n < steps; ++n)
      integrator.step(m, s, h);
    return s;
  };
  const State reference = generic(IntegratorKind::rk4, dt / 10, model);
  const double travel = (reference.x - start.x).norm();
  ASSERT_GT(travel, 1e-5);
  for (const IntegratorKind kind :
       {IntegratorKind::explicit_euler, IntegratorKind::symplectic_euler,
        IntegratorKind::central_difference, IntegratorKind::rk4, IntegratorKind::implicit_euler}) {
    const State s = generic(kind, dt, model);
    EXPECT_LT((s.x - reference.x).norm(), 0.05 * travel) << to_string(kind);
  }
  for (const IntegratorKind kind :
       {IntegratorKind::explicit_euler, IntegratorKind::symplectic_euler, IntegratorKind::rk4}) {
    const State expected = generic(kind, dt, model);
    FastStepperOptions options;
    options.integrator = kind;
    FastExplicitStepper fast(model, options);
    fast.set_state(start);
    g.grasper->move_to(first);
    fast.step(dt, half);
    g.grasper->move_to(second);
    fast.step(dt, half);
    EXPECT_LT((fast.state().x - expected.x).norm(), 1e-9 * travel) << to_string(kind);
  }
  const double h = 1e-3;
  Integrator backward(IntegratorKind::implicit_euler, {1e-13, 5000});
  State expected = start;
  FastImplicitStepper fast(model, FastImplicitOptions{2, true, 1e-13, 5000});
  fast.set_state(start);
  for (const Eigen::Vector3d& point : {first, second}) {
    g.grasper->move_to(point);
    for (int n = 0; n < 5; ++n) {
      backward.step(model, expected, h);
      fast.step(h);
    }
  }
  const double backward_travel = (expected.x - start.x).norm();
  ASSERT_GT(backward_travel, 1e-5);
  EXPECT_LT((fast.state().x - expected.x).norm(), 1e-8 * backward_travel);
  MassSpringModel blind = model;
  blind.clear_fields<Grasper>();
  EXPECT_GT((generic(IntegratorKind::rk4, dt, blind).x - reference.x).norm(), 0.5 * travel);
}

// The stability estimate's ω_max² against a dense eigensolve of M^-½ K M^-½ on the free dofs, with
// a grasper stiff enough that its mode is the highest; the modal damping fit on a given shape
// against its closed form, the grasper's spring and dashpot adding k |Σ u|²/n² and c |Σ u|²/n²
// (u mass-normalised, Σ over the grasped nodes) to ω² and 2ωζ.
TEST(OutsideField, StabilityAndModalDampingSeeIt) {
  Grasped g = grasped_sphere(3e4, 0.3, 0.0);
  const MassSpringModel& model = g.model;
  const Eigen::VectorXd x = model.initial_state();
  const Eigen::MatrixXd k = -Eigen::MatrixXd(model.dfdx(x, 0 * x, Linearisation::definite));
  const Eigen::VectorXd mass = model.mass_per_dof();
  std::vector<int> free;
  for (int i = 0; i < model.num_nodes(); ++i)
    for (int d = 0; d < 3 && !model.is_constrained(i); ++d)
      free.push_back(3 * i + d);
  const int n = static_cast<int>(free.size());
  Eigen::MatrixXd scaled(n, n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
      scaled(r, c) = k(free[r], free[c]) / std::sqrt(mass[free[r]] * mass[free[c]]);
  const double dense =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled).eigenvalues().maxCoeff();
  const SpectralEstimate estimate = estimate_max_eigenvalue(model, x, 2000, 1e-10);
  EXPECT_NEAR(estimate.max_eigenvalue / dense, 1.0, 1e-6);
  MassSpringModel blind = model;
  blind.clear_fields<Grasper>();
  EXPECT_LT(estimate_max_eigenvalue(blind, x, 2000, 1e-10).max_eigenvalue, 0.9 * dense);

  // Shape: the grasped nodes moved up by 1 (the grasp's own motion).
  Eigen::VectorXd shape = Eigen::VectorXd::Zero(x.size());
  for (int i : g.grasper->nodes())
    shape[3 * i + 2] = 1.0;
  double norm2 = 0.0;
  for (int i : g.grasper->nodes())
    norm2 += model.network().masses[i];
  const double sum2 = 25.0 / norm2;  // |Σ u_z|² with u = shape / sqrt(shapeᵀ M shape)
  const DampingFit with = fit_damping(model, x, 0.5, shape);
  const DampingFit without = fit_damping(blind, x, 0.5, shape);
  const double omega = 2 * M_PI * with.frequency_hz, omega0 = 2 * M_PI * without.frequency_hz;
  EXPECT_NEAR((omega * omega - omega0 * omega0) / (3e4 * sum2 / 25.0), 1.0, 1e-9);
  const double zeta0 = with.target - with.case_damping_ratio * with.modal_ratio_per_unit_r;
  const double zeta0_blind =
      without.target - without.case_damping_ratio * without.modal_ratio_per_unit_r;
  EXPECT_NEAR((2 * omega * zeta0 - 2 * omega0 * zeta0_blind) / (0.3 * sum2 / 25.0), 1.0, 1e-9);
}

}  // namespace
}  // namespace msfem::massspring
