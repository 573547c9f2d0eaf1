// The fast explicit stepper's RK4 is the generic Integrator's RK4 on the node-centric kernels: the
// same states to round-off in double, for every spring-damping path, supports and a pushed node,
// on one thread or two; fourth order in the step; divergence reported with RK4's stable step.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "icosphere.hpp"
#include "msfem/massspring/errors.hpp"
#include "msfem/massspring/fast_stepper.hpp"
#include "msfem/massspring/mass_spring_model.hpp"
#include "msfem/massspring/stability.hpp"
#include "msfem/massspring/topology_builders.hpp"

namespace msfem::massspring {
namespace {

enum class Damping { none, uniform, per_spring };

// Damped three-tier sphere: tier 3 fixed, gravity, a nodal load and one surface node pushed in
// (a prescribed displacement, so the run starts out of balance).
MassSpringModel loaded_three_tier(Damping damping, int level = 2) {
  const auto mesh = testing::icosphere(level, 0.05);
  ThreeTierOptions options;
  options.material.spring_damping = damping == Damping::none ? 0.0 : 0.01;
  options.material.node_damping = 0.002;
  MassSpringModel model(build_three_tier(mesh.vertices, mesh.triangles, options));
  if (damping == Damping::per_spring) {
    Eigen::VectorXd c(model.network().num_springs());
    for (Eigen::Index s = 0; s < c.size(); ++s)
      c[s] = 0.005 * (1 + s % 3);
    model.set_damping(c);
  }
  model.set_gravity({0.0, -9.81, 0.0});
  model.set_external_force(5, {0.0, 0.0, 0.01});
  model.prescribe_displacement(model.network().surface_nodes.back(), {0.0, 0.0, -0.002});
  return model;
}

FastStepperOptions rk4_options(int threads, bool single_precision = false) {
  FastStepperOptions options;
  options.threads = threads;
  options.single_precision = single_precision;
  options.integrator = IntegratorKind::rk4;
  options.adaptive_threads = false;
  return options;
}

State generic_run(const MassSpringModel& model, IntegratorKind kind, double dt, int steps) {
  Integrator integrator(kind);
  State state = initial_state(model);
  for (int n = 0; n < steps; ++n)
    integrator.step(model, state, dt);
  return state;
}

// |a - b| relative to how far b has moved from `start`.
double relative_x(const State& a, const State& b, const Eigen::VectorXd& start) {
  return (a.x - b.x).norm() / (b.x - start).norm();
}
double relative_v(const State& a, const State& b) {
  return (a.v - b.v).norm() / b.v.norm();
}

double half_central_difference_step(const MassSpringModel& model) {
  return 0.5 *
         predicted_stable_dt(model, IntegratorKind::central_difference, model.initial_state());
}

TEST(FastRk4, MatchesGenericRk4ForEveryDampingInDoubleAndFloat) {
  for (const Damping damping : {Damping::none, Damping::uniform, Damping::per_spring}) {
    const MassSpringModel model = loaded_three_tier(damping);
    const Eigen::VectorXd rest = model.rest_state();
    const double dt = half_central_difference_step(model);
    const State reference = generic_run(model, IntegratorKind::rk4, dt, 300);
    ASSERT_GT((reference.x - rest).norm(), 1e-4);
    const int label = static_cast<int>(damping);
    FastExplicitStepper one(model, rk4_options(1)), two(model, rk4_options(2));
    for (FastExplicitStepper* fast : {&one, &two}) {
      fast->step(dt, 100);
      fast->step(dt, 200);
      const State state = fast->state();
      EXPECT_LE(relative_x(state, reference, rest), 1e-9) << label << " " << fast->threads();
      EXPECT_LE(relative_v(state, reference), 1e-9) << label << " " << fast->threads();
      EXPECT_NEAR(state.time, reference.time, 1e-12);
    }
    // Four passes, each with more records than an Euler step's one.
    EXPECT_GT(one.streamed_bytes_per_step(),
              4 * FastExplicitStepper(model).streamed_bytes_per_step());
    // Each node is updated by the same arithmetic on any thread.
    EXPECT_EQ((one.state().x - two.state().x).cwiseAbs().maxCoeff(), 0.0) << label;
    // Float on its widest lanes and on AVX2's 8.
    for (const bool allow_avx512 : {true, false}) {
      FastStepperOptions options = rk4_options(2, true);
      options.allow_avx512 = allow_avx512;
      FastExplicitStepper single(model, options);
      single.step(dt, 300);
      EXPECT_LE(relative_x(single.state(), reference, rest), 2e-5) << label;
    }
    // Not another scheme under RK4's name: symplectic Euler ends measurably elsewhere.
    const State symplectic = generic_run(model, IntegratorKind::symplectic_euler, dt, 300);
    EXPECT_GT(relative_x(symplectic, reference, rest), 1e-4) << label;
  }
}

// Stiffness and a support target changed between calls reach every stage's buffers.
TEST(FastRk4, FollowsStiffnessAndSupportChanges) {
  MassSpringModel model = loaded_three_tier(Damping::uniform);
  const Eigen::VectorXd rest = model.rest_state();
  const double dt = half_central_difference_step(model);
  FastExplicitStepper fast(model, rk4_options(2));
  Integrator integrator(IntegratorKind::rk4);
  State reference = initial_state(model);
  fast.step(dt, 50);
  for (int n = 0; n < 50; ++n)
    integrator.step(model, reference, dt);
  model.scale_group_stiffness("tier1_edges", 0.5);
  model.prescribe_displacement(model.network().surface_nodes.back(), {0.0, 0.001, -0.004});
  fast.update_parameters(model);
  model.enforce_constraints(reference.x, reference.v);  // the stepper moves supports at once
  fast.step(dt, 150);
  for (int n = 0; n < 150; ++n)
    integrator.step(model, reference, dt);
  EXPECT_LE(relative_x(fast.state(), reference, rest), 1e-9);
  EXPECT_LE(relative_v(fast.state(), reference), 1e-9);
}

// Halving the step divides the error at a fixed time by about 2⁴ = 16. The reference is the same
// stepper at a sixteenth of the coarsest step, whose own error is 16⁴ times smaller than the
// coarsest's. A random start excites every mode, the highest included.
TEST(FastRk4, ConvergesAtFourthOrder) {
  const MassSpringModel model = loaded_three_tier(Damping::uniform, 1);
  const double coarse = 0.5 * half_central_difference_step(model);
  State start = initial_state(model);
  Eigen::VectorXd kick = Eigen::VectorXd::Random(start.v.size());
  model.zero_constrained(kick);
  start.v += 0.05 * kick;
  const int steps = 40;  // at the coarsest step  // at the coarsest step
  auto run = [&](int refinement) {
    FastExplicitStepper fast(model, rk4_options(1));
    fast.set_state(start);
    fast.step(coarse / refinement, steps * refinement);
    return fast.state();
  };
  const State reference = run(16);
  double error[3];
  for (int level = 0; level < 3; ++level)
    error[level] = (run(1 << level).x - reference.x).norm();
  // Far above round-off (ε |x| per step: about 1e-14 over these steps).
  ASSERT_GT(error[2], 1e-10 * reference.x.norm());
  for (int level = 0; level < 2; ++level) {
    const double order = std::log2(error[level] / error[level + 1]);
    EXPECT_GT(order, 3.5) << level;
    EXPECT_LT(order, 4.5) << level;
  }
}

TEST(FastRk4, DivergenceReportsRk4sStableStep) {
  const MassSpringModel model = loaded_three_tier(Damping::uniform);
  const double stable = predicted_stable_dt(model, IntegratorKind::rk4, model.initial_state());
  FastExplicitStepper fast(model, rk4_options(2));
  try {
    for (int call = 0; call < 100; ++call)
      fast.step(3.0 * stable, 50);
    FAIL() << "no divergence detected";
  } catch (const DivergenceError& error) {
    EXPECT_NEAR(error.stable_dt() / stable, 1.0, 1e-9);
  }
}

TEST(FastRk4, OtherIntegratorsAreRefusedByName) {
  const MassSpringModel model = loaded_three_tier(Damping::none, 1);
  for (const IntegratorKind kind :
       {IntegratorKind::central_difference, IntegratorKind::implicit_euler}) {
    FastStepperOptions options;
    options.integrator = kind;
    try {
      FastExplicitStepper fast(model, options);
      ADD_FAILURE() << to_string(kind) << " accepted";
    } catch (const ModelError& error) {
      EXPECT_NE(std::string(error.what()).find(to_string(kind)), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace msfem::massspring
